#include "swarmbox/radio/link_probe.hpp"

#include <algorithm>
#include <utility>

#include "swarmbox/bus/topics.hpp"
#include "swarmbox/radio/link_event.hpp"

namespace swarmbox::radio {

Result<std::unique_ptr<LinkProbe>> LinkProbe::Create(std::string self, std::vector<std::string> peers,
                                                     LinkProbeOptions options, TimePoint start) {
  if (auto s = bus::ValidateDroneName(self); !s) return s.error().Context("link probe");
  if (options.ping_every.count() <= 0 || options.timeout.count() <= 0 || options.report_every.count() <= 0) {
    return Error(ErrorCode::kInvalidArgument,
                 "link probe: ping_every, timeout and report_every must be positive (got " +
                     std::to_string(options.ping_every.count()) + " ms, " +
                     std::to_string(options.timeout.count()) + " ms, " +
                     std::to_string(options.report_every.count()) + " ms)");
  }
  if (options.ping_peers <= 0) {
    return Error(ErrorCode::kInvalidArgument,
                 "link probe: ping_peers must be positive (got " + std::to_string(options.ping_peers) + ")");
  }
  std::vector<std::string> unique;
  for (std::string& p : peers) {
    if (auto s = bus::ValidateDroneName(p); !s) return s.error().Context("link probe: peer");
    if (p == self || std::find(unique.begin(), unique.end(), p) != unique.end()) continue;
    unique.push_back(std::move(p));
  }
  if (unique.empty())
    return Error(ErrorCode::kInvalidArgument, "link probe: no peer to ping besides '" + self + "'");
  return std::unique_ptr<LinkProbe>(new LinkProbe(std::move(self), std::move(unique), options, start));
}

LinkProbe::LinkProbe(std::string self, std::vector<std::string> peers, LinkProbeOptions options,
                     TimePoint start)
    : self_(std::move(self)),
      monitor_(std::move(peers),
               LinkMonitorOptions{.ping_every = options.ping_every,
                                  .timeout = options.timeout,
                                  .report_every = options.report_every,
                                  .ping_peers = static_cast<std::size_t>(options.ping_peers)},
               start) {
  due_.reserve(std::min(monitor_.peers().size(), static_cast<std::size_t>(options.ping_peers)));
  out_.ping_msg.resize(1);
  out_.ping_msg[0].from = self_;
}

void LinkProbe::OnFrame(const bus::RadioFrame& frame, MeshRadio& radio) {
  for (const bus::RadioPing& m : frame.ping_msg) {
    if (m.to != self_ || m.from == self_) {
      ++counters_.ignored;
      continue;
    }
    if (!m.is_pong) {
      bus::RadioPing& pong = out_.ping_msg[0];
      out_.to = m.from;
      pong.to = m.from;
      pong.seq = m.seq;
      pong.sent_ns = m.sent_ns;
      pong.is_pong = true;
      radio.Send(out_);
      ++counters_.pongs_sent;
      continue;
    }
    ++counters_.pongs_received;
    const PongResult r = monitor_.OnPong(m.from, m.seq, RadioTime(frame.delivered_ns));
    if (r == PongResult::kUnknownPeer || r == PongResult::kUnknownSeq) ++counters_.ignored;
  }
}

void LinkProbe::Step(TimePoint now, double sim_t_s, MeshRadio& radio, std::vector<LogEvent>* lines) {
  due_.clear();
  monitor_.DuePings(now, due_);  // recorded as sent at `now`
  bus::RadioPing& ping = out_.ping_msg[0];
  for (const PingToSend& p : due_) {
    out_.to = monitor_.peers()[p.peer];
    ping.to = out_.to;
    ping.seq = p.seq;
    ping.sent_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch()).count();
    ping.is_pong = false;
    radio.Send(out_);
    ++counters_.pings_sent;
  }
  if (auto report = monitor_.TakeReport(now)) {
    for (const LinkWindow& w : *report) {
      if (w.sent > 0) lines->push_back(FormatLinkEvent(sim_t_s, self_, w));
    }
  }
}

}  // namespace swarmbox::radio
