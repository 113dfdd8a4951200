// LinkProbe: what the radio actually does, measured by every agent over its MeshRadio (whichever
// model: channel or netem). Every `ping_every` of the radio's clock it pings `ping_peers` of its
// peers, round-robin (those heard in the last 5 s first, by name, then the others: LinkMonitor's
// "Sampling"), so its cost is constant in the swarm's size; it answers the pings addressed to it,
// matches pongs by (peer, seq) in a LinkMonitor (link_monitor.hpp) and returns per sampled peer
// per report window an `event=link` line (link_event.hpp).
//
//   auto probe = LinkProbe::Create("scout_1", {"scout_1", "scout_2", "scout_3"},
//                                  {.ping_every = 200ms, .ping_peers = 3}, RadioTime(radio.now_ns()));
//   // every lockstep step, after radio.TakeReceived(sample, &frames):
//   for (const bus::RadioFrame& f : frames) probe->Heard(f);                  // the sampling order
//   for (const bus::RadioFrame& f : frames) if (!f.ping_msg.empty()) probe->OnFrame(f, radio);
//   probe->Step(RadioTime(radio.now_ns()), sim_t_s, radio, &lines);   // due pings, reports
//
// The clock is the radio's (MeshRadio::now_ns()): simulated time with radio.model channel (the
// RTTs are then simulated ms, reproducible at any rtf), the steady clock with netem (wall ms, as
// RadioLink measured before). A pong's receive time is its frame's delivered_ns, on that same
// clock (the channel's delivery time; the moment the middleware handed it over with netem).
// Pings are answered when the control loop dispatches them, i.e. at the step they are delivered
// at: with channel the pong leaves at t_k for a ping delivered in (t_{k-1}, t_k]; with netem at
// the next control step after arrival (up to one step, 4 ms at rtf 1, in the peer's RTT). The
// answer is sent from the control loop, never from a middleware callback, so no sender thread is
// needed (RadioLink had one: Cyclone delivers own-process writes synchronously to readers).
//
// Wire protocol (one bus::RadioPing per frame, addressed to its peer): a ping carries `from`,
// `to`, a per-peer `seq` and `sent_ns` (the radio's clock); the pong swaps from/to, copies seq and
// sent_ns and sets is_pong. A ping addressed to us from anyone is answered; pongs are counted only
// from the peers we ping. Pure: no DDS, no clock, no threads; not thread-safe (the control loop).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/radio/link_monitor.hpp"
#include "swarmbox/radio/mesh_radio.hpp"

namespace swarmbox::radio {

// A radio clock reading [ns] as a LinkMonitor time point.
inline TimePoint RadioTime(std::int64_t ns) { return TimePoint(std::chrono::nanoseconds(ns)); }

struct LinkProbeOptions {
  std::chrono::milliseconds ping_every{200};     // one round of pings, radio clock (--ping-every-ms), > 0
  std::chrono::milliseconds timeout{1000};       // a ping unanswered this long is lost, > 0
  std::chrono::milliseconds report_every{2000};  // one event=link line per peer per window, > 0
  int ping_peers = 3;                            // peers per round (--ping-peers), > 0
};

class LinkProbe {
 public:
  struct Counters {
    std::uint64_t pings_sent = 0;      // pings handed to the radio
    std::uint64_t pongs_sent = 0;      // pongs we sent for others' pings
    std::uint64_t pongs_received = 0;  // pongs addressed to us (any outcome)
    std::uint64_t ignored = 0;         // pings/pongs for others, our own, refused pongs
  };

  // `peers` may contain `self` (the trial's member list): it is dropped, as are repeats.
  // kInvalidArgument for a bad drone name (bus::ValidateDroneName), a non-positive option or no
  // peer left. The first pings are due at `start`, the first report one window later.
  // peers() is sorted by name.
  static Result<std::unique_ptr<LinkProbe>> Create(std::string self, std::vector<std::string> peers,
                                                   LinkProbeOptions options, TimePoint start);

  // A frame the radio delivered carrying a RadioPing (frames without one are ignored). A ping to
  // us is answered at once through `radio` (Send); a pong goes to the monitor, received at the
  // frame's delivered_ns.
  void OnFrame(const bus::RadioFrame& frame, MeshRadio& radio);
  // Any frame the radio delivered (state, Raft, ping, ...): its sender counts as heard at the
  // frame's delivered_ns, for the sampling order. O(log peers), no allocation.
  void Heard(const bus::RadioFrame& frame) { monitor_.Heard(frame.from, RadioTime(frame.delivered_ns)); }
  // At `now` (the radio's clock): sends the due pings through `radio` and, when a report window
  // ended, appends its link lines stamped with `sim_t_s` to `lines` (peers with nothing settled
  // get none). Allocates only when a window ends.
  void Step(TimePoint now, double sim_t_s, MeshRadio& radio, std::vector<LogEvent>* lines);

  const Counters& counters() const { return counters_; }
  const std::string& self() const { return self_; }
  const std::vector<std::string>& peers() const { return monitor_.peers(); }

 private:
  LinkProbe(std::string self, std::vector<std::string> peers, LinkProbeOptions options, TimePoint start);

  std::string self_;
  LinkMonitor monitor_;
  Counters counters_;
  std::vector<PingToSend> due_;
  bus::RadioFrame out_;  // reused: one RadioPing element
};

}  // namespace swarmbox::radio
