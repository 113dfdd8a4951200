#include "swarmbox/radio/link_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "swarmbox/common/result.hpp"

namespace swarmbox::radio {
namespace {

// Settled pings are remembered this many timeouts after sending, so a pong that comes later than
// its timeout is still recognised as late (and a repeated one as a duplicate).
constexpr int kRememberTimeouts = 4;

double Ms(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

}  // namespace

double NearestRankPercentile(const std::vector<double>& sorted, double p) {
  SWARMBOX_CHECK(!sorted.empty() && p > 0.0 && p <= 1.0);
  const double rank = std::ceil(p * static_cast<double>(sorted.size()));
  const auto index = static_cast<std::size_t>(std::max(rank, 1.0)) - 1;
  return sorted[std::min(index, sorted.size() - 1)];
}

RttSummary SummariseRtt(const std::vector<double>& samples_ms) {
  RttSummary s;
  s.count = samples_ms.size();
  if (samples_ms.empty()) return s;
  std::vector<double> sorted = samples_ms;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0.0;
  for (double v : sorted) sum += v;
  const double n = static_cast<double>(sorted.size());
  s.mean_ms = sum / n;
  if (sorted.size() > 1) {
    double sq = 0.0;
    for (double v : sorted) sq += (v - s.mean_ms) * (v - s.mean_ms);
    s.sd_ms = std::sqrt(sq / (n - 1.0));
  }
  s.p50_ms = NearestRankPercentile(sorted, 0.50);
  s.p99_ms = NearestRankPercentile(sorted, 0.99);
  s.max_ms = sorted.back();
  return s;
}

LinkMonitor::LinkMonitor(std::vector<std::string> peers, LinkMonitorOptions options, TimePoint start)
    : peers_(std::move(peers)),
      options_(options),
      state_(peers_.size()),
      next_ping_(start),
      next_report_(start + options.report_every),
      cursor_(0),
      taken_round_(peers_.size(), 0) {
  SWARMBOX_CHECK(options_.ping_every.count() > 0 && options_.timeout.count() > 0 &&
                 options_.report_every.count() > 0 && options_.heard_within.count() > 0);
  std::sort(peers_.begin(), peers_.end());
  SWARMBOX_CHECK(std::adjacent_find(peers_.begin(), peers_.end()) == peers_.end());
  // At most the pings of one window plus those carried over from the last settle in a window: the
  // RTT samples then do not reallocate in the steady state.
  const auto per_window = static_cast<std::size_t>(options_.report_every / options_.ping_every +
                                                   options_.timeout / options_.ping_every) + 2;
  for (std::size_t i = 0; i < peers_.size(); ++i) {
    state_[i].window.peer = peers_[i];
    state_[i].rtt_ms.reserve(per_window);
  }
}

void LinkMonitor::Heard(std::string_view peer, TimePoint at) {
  const std::optional<std::size_t> index = FindPeer(peer);
  if (!index) return;
  Peer& p = state_[*index];
  if (!p.heard || at > p.heard_at) p.heard_at = at;
  p.heard = true;
}

bool LinkMonitor::Recent(const Peer& p, TimePoint now) const {
  return p.heard && now - p.heard_at < options_.heard_within;
}

std::optional<std::size_t> LinkMonitor::NextSampled(TimePoint now, std::size_t taken) {
  const std::size_t n = state_.size();
  if (taken >= n) return std::nullopt;
  // Two passes (recent, then the others) cover every peer once: a peer not yet taken this round
  // is found within 2 n looks.
  for (std::size_t looked = 0; looked < 2 * n; ++looked) {
    const std::size_t i = cursor_;
    const int pass = pass_;
    if (++cursor_ == n) {
      cursor_ = 0;
      pass_ ^= 1;
    }
    if (taken_round_[i] == round_) continue;
    if (Recent(state_[i], now) == (pass == 0)) return i;
  }
  return std::nullopt;
}

void LinkMonitor::DuePings(TimePoint now, std::vector<PingToSend>& out) {
  if (now < next_ping_) return;
  auto ping = [&](std::size_t i) {
    Peer& p = state_[i];
    Forget(p, now);
    const std::uint64_t seq = p.next_seq++;
    p.entries.push_back(Entry{seq, now, State::kPending});
    out.push_back(PingToSend{i, seq});
  };
  const std::size_t k = options_.ping_peers;
  if (k == 0 || k >= state_.size()) {
    for (std::size_t i = 0; i < state_.size(); ++i) ping(i);  // every peer, every round
  } else {
    ++round_;
    for (std::size_t taken = 0; taken < k; ++taken) {
      const std::optional<std::size_t> i = NextSampled(now, taken);
      if (!i) break;
      taken_round_[*i] = round_;
      ping(*i);
    }
  }
  next_ping_ += options_.ping_every;
  if (next_ping_ <= now) next_ping_ = now + options_.ping_every;
}

PongResult LinkMonitor::OnPong(std::string_view peer, std::uint64_t seq, TimePoint received) {
  const std::optional<std::size_t> index = FindPeer(peer);
  if (!index) {
    ++refused_;
    return PongResult::kUnknownPeer;
  }
  Peer& p = state_[*index];
  if (seq == 0 || seq >= p.next_seq) {
    ++refused_;
    return PongResult::kUnknownSeq;
  }
  if (p.entries.empty() || seq < p.entries.front().seq) {
    ++p.window.late;  // settled and forgotten long ago
    return PongResult::kLate;
  }
  Entry& e = p.entries[static_cast<std::size_t>(seq - p.entries.front().seq)];
  switch (e.state) {
    case State::kAnswered:
      ++p.window.duplicates;
      return PongResult::kDuplicate;
    case State::kLost:
      ++p.window.late;
      return PongResult::kLate;
    case State::kPending:
      break;
  }
  ++p.window.sent;
  if (received - e.sent >= options_.timeout) {
    e.state = State::kLost;
    ++p.window.late;
    return PongResult::kLate;
  }
  e.state = State::kAnswered;
  ++p.window.received;
  p.rtt_ms.push_back(Ms(received - e.sent));
  return PongResult::kMatched;
}

std::optional<std::vector<LinkWindow>> LinkMonitor::TakeReport(TimePoint now) {
  if (now < next_report_) return std::nullopt;
  std::vector<LinkWindow> report;
  report.reserve(state_.size());
  for (Peer& p : state_) {
    SettleExpired(p, now);
    p.window.rtt = SummariseRtt(p.rtt_ms);
    report.push_back(p.window);
    p.window = LinkWindow{};
    p.window.peer = report.back().peer;
    p.rtt_ms.clear();
  }
  next_report_ += options_.report_every;
  if (next_report_ <= now) next_report_ = now + options_.report_every;
  return report;
}

void LinkMonitor::SettleExpired(Peer& p, TimePoint now) {
  std::size_t i = p.first_pending;
  while (i < p.entries.size()) {
    Entry& e = p.entries[i];
    if (e.state == State::kPending) {
      if (now - e.sent < options_.timeout) break;  // later entries were sent later still
      e.state = State::kLost;
      ++p.window.sent;
    }
    ++i;
  }
  p.first_pending = i;
}

void LinkMonitor::Forget(Peer& p, TimePoint now) {
  SettleExpired(p, now);
  const auto remember = options_.timeout * kRememberTimeouts;
  while (p.first_pending > 0 && now - p.entries.front().sent >= remember) {
    p.entries.pop_front();
    --p.first_pending;
  }
}

std::optional<std::size_t> LinkMonitor::FindPeer(std::string_view name) const {
  const auto it = std::lower_bound(peers_.begin(), peers_.end(), name,
                                   [](const std::string& a, std::string_view b) { return a < b; });
  if (it == peers_.end() || *it != name) return std::nullopt;
  return static_cast<std::size_t>(it - peers_.begin());
}

}  // namespace swarmbox::radio
