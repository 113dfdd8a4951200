// LinkMonitor: the pure bookkeeping of the radio ping protocol (no DDS, no clock of its own):
// when to ping which peer, matching pongs to pings by (peer, seq), and per-peer figures over
// report windows: pings settled, pongs received in time, loss, RTT mean/p50/p99.
//
//   LinkMonitor m({"scout_2", "scout_3"}, {.ping_every = 200ms, .timeout = 1s, .ping_peers = 3}, start);
//   std::vector<PingToSend> due;
//   m.Heard("scout_2", at);                      // any frame from a peer (sampling order, below)
//   m.DuePings(now, due);                        // {peer, seq} to publish now; recorded as sent
//   m.OnPong("scout_2", seq, received_at);        // kMatched, kLate, kDuplicate, ...
//   if (auto windows = m.TakeReport(now)) { ... } // every report_every: one LinkWindow per peer
//
// Settling rule (what `sent`, `received` and `loss` mean): a ping is settled either when its pong
// arrives within `timeout` of sending (received, with an RTT sample) or when `timeout` has passed
// without one (lost). A window counts the pings settled during it: sent = settled pings, received
// = the answered ones, loss = 1 - received / sent. A ping still pending at the end of a window is
// carried into the next, so no ping is counted twice or dropped and the loss estimate is unbiased
// (a window does not count as lost what merely has not come back yet).
// A pong after its ping's timeout is `late` (the ping stays lost); a second pong for an answered
// ping is a `duplicate`; neither changes sent/received/RTT. Pongs for seqs older than the pings
// still remembered (about 4 x timeout) count as late. A pong for a seq never sent, or from a name
// that is not a peer, is refused (kUnknownSeq, kUnknownPeer) and counted in `refused()`.
//
// Sampling (what keeps a drone's ping cost constant in the swarm's size): every `ping_every` a
// round pings `ping_peers` peers (0 = every peer, each round), chosen round-robin over one cycle:
// first the peers heard within `heard_within` (5 s; Heard(), any frame from them), by name, then
// the others (never heard, or silent longer), by name; the next round goes on where the last one
// stopped. With ping_peers >= the number of peers every peer is pinged every round, as before
// sampling. A silent peer is still pinged in its turn, so a partition shows as loss.
//
// Times are std::chrono::steady_clock time points given by the caller (the radio's clock in the
// agent: simulated or steady, link_probe.hpp; synthetic in tests). Not thread-safe: the caller
// serialises (LinkProbe runs on the control loop).
// Allocation: DuePings and OnPong do not allocate once warm (DuePings appends to the caller's
// vector); TakeReport allocates the report.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace swarmbox::radio {

using TimePoint = std::chrono::steady_clock::time_point;

struct LinkMonitorOptions {
  std::chrono::milliseconds ping_every{200};     // one round of pings per period, > 0
  std::chrono::milliseconds timeout{1000};       // unanswered this long: lost, > 0
  std::chrono::milliseconds report_every{2000};  // report window length, > 0
  std::size_t ping_peers = 0;                    // peers pinged per round; 0 = every peer
  std::chrono::milliseconds heard_within{5000};  // "heard recently" for the sampling order, > 0
};

struct PingToSend {
  std::size_t peer = 0;    // index into LinkMonitor::peers()
  std::uint64_t seq = 0;   // per peer, 1, 2, 3, ...
  bool operator==(const PingToSend&) const = default;
};

// RTT figures of one window [ms]; all zero when count == 0.
struct RttSummary {
  std::size_t count = 0;
  double mean_ms = 0.0;
  double sd_ms = 0.0;    // sample standard deviation (0 for one sample)
  double p50_ms = 0.0;   // nearest-rank percentiles
  double p99_ms = 0.0;
  double max_ms = 0.0;
};

// One peer's figures over one report window (see the settling rule above).
struct LinkWindow {
  std::string peer;
  std::uint64_t sent = 0;        // pings settled in the window
  std::uint64_t received = 0;    // of those, answered within the timeout
  std::uint64_t late = 0;        // pongs that came after their ping's timeout
  std::uint64_t duplicates = 0;  // extra pongs for pings already answered
  RttSummary rtt;                // over the `received` pongs
  // 1 - received / sent; 0 when nothing was settled.
  double loss() const {
    return sent == 0 ? 0.0 : 1.0 - static_cast<double>(received) / static_cast<double>(sent);
  }
};

enum class PongResult { kMatched, kLate, kDuplicate, kUnknownPeer, kUnknownSeq };

// Nearest-rank percentile (p in (0, 1]) of `sorted` (ascending, not empty): sorted[ceil(p n) - 1].
double NearestRankPercentile(const std::vector<double>& sorted, double p);
// Mean, sd, p50, p99, max of `samples_ms` (any order; copied and sorted).
RttSummary SummariseRtt(const std::vector<double>& samples_ms);

class LinkMonitor {
 public:
  // `peers`: distinct names (the caller validates and removes self); kept sorted by name (peers()).
  // Options must be positive (checked: aborts on a broken invariant). The first pings are due at
  // `start`, the first report at start + report_every.
  LinkMonitor(std::vector<std::string> peers, LinkMonitorOptions options, TimePoint start);

  // A frame from `peer` arrived at `at` (any kind): it counts as heard for the sampling order.
  // Names that are not peers are ignored. O(log peers).
  void Heard(std::string_view peer, TimePoint at);

  // When a ping round is due at `now`, appends one PingToSend per sampled peer (ping_peers of them,
  // or every peer; see Sampling above) to `out` and records them as sent at `now`. A late call
  // sends one round, not a burst: the next round is then due one period after `now`.
  void DuePings(TimePoint now, std::vector<PingToSend>& out);

  // A pong from `peer` for `seq`, received at `received`.
  PongResult OnPong(std::string_view peer, std::uint64_t seq, TimePoint received);

  // When a report is due at `now` (report_every since the last): settles the pings whose timeout
  // has passed, and returns one LinkWindow per peer (in peers() order, also peers with nothing
  // settled: sent == 0), starting a new window. nullopt when no report is due. O(peers), once per
  // window.
  std::optional<std::vector<LinkWindow>> TakeReport(TimePoint now);

  // When the next ping round is due (DuePings does nothing before).
  const std::vector<std::string>& peers() const { return peers_; }
  std::uint64_t refused() const { return refused_; }
  const LinkMonitorOptions& options() const { return options_; }

 private:
  enum class State : std::uint8_t { kPending, kAnswered, kLost };
  struct Entry {
    std::uint64_t seq = 0;
    TimePoint sent;
    State state = State::kPending;
  };
  struct Peer {
    std::uint64_t next_seq = 1;
    std::deque<Entry> entries;       // consecutive seqs, oldest first
    std::size_t first_pending = 0;   // entries before this index are settled
    LinkWindow window;
    std::vector<double> rtt_ms;      // this window's samples
    bool heard = false;              // Heard() at least once
    TimePoint heard_at;              // the last time
  };

  void SettleExpired(Peer& p, TimePoint now);
  void Forget(Peer& p, TimePoint now);
  std::optional<std::size_t> FindPeer(std::string_view name) const;
  bool Recent(const Peer& p, TimePoint now) const;
  // The next peer of the sampling cycle after the cursor (advanced), or nullopt when `taken` has
  // them all; see Sampling above.
  std::optional<std::size_t> NextSampled(TimePoint now, std::size_t taken);

  std::vector<std::string> peers_;
  LinkMonitorOptions options_;
  std::vector<Peer> state_;
  TimePoint next_ping_;
  TimePoint next_report_;
  std::uint64_t refused_ = 0;
  // The sampling cycle's cursor: the pass (0: heard recently, 1: the others) and the last peer
  // index taken in it (n: none yet); round_ marks the peers taken this round (no repeats).
  int pass_ = 0;
  std::size_t cursor_;
  std::vector<std::uint64_t> taken_round_;
  std::uint64_t round_ = 0;
};

}  // namespace swarmbox::radio
