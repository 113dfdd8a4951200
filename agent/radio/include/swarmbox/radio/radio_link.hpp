// RadioLink: what the radio actually does, measured by every agent. It pings each peer over the
// mesh (bus::RadioPing on bus::kRadioPingTopic, Qos::kRadio: best effort, so loss stays visible)
// on wall-clock time, answers pings addressed to it at once, matches pongs by (peer, seq) and
// reports per peer per window an `event=link` line (link_event.hpp) with sent, received, loss and
// RTT mean/p50/p99.
//
//   auto link = RadioLink::Create(*mesh, "scout_1", {"scout_1", "scout_2", "scout_3"},
//                                 {.ping_every = std::chrono::milliseconds(200)});
//   if (!link) return link.error();               // bad name, bad options, bus errors
//   for (const LogEvent& e : (*link)->Poll(std::chrono::steady_clock::now(), sim_t_s)) Log(e);
//
// A sender thread of its own publishes the pings when due and the pongs the moment a ping arrives,
// so neither depends on how often the host polls (nor on the lockstep). It exists because a sample
// cannot be published from the reader's callback: Cyclone DDS delivers a write to the readers of the
// same process synchronously, and our own reader on the ping topic would wait for its own running
// callback (a deadlock). Poll() is cheap and meant to be called often (every lockstep sample): at
// the end of each report window it returns the link lines stamped with `sim_t_s` (peers with
// nothing settled in the window get no line); otherwise an empty vector (no allocation).
// Pong receive times are taken on the middleware thread the moment the sample is delivered.
//
// One writer per peer for pings and one per peer for pongs: a best-effort DDS reader drops a
// sample that arrives after a later one of the same writer (RTPS sequence numbers; Cyclone does),
// so with a jittered radio (netem or the NFQUEUE delayer reorder packets) one shared writer would
// turn reordering between pings and pongs to different peers into loss (measured: 43.5 % "loss"
// with one writer at 100 +- 20 ms / 5 % loss, and RTTs biased low, as the overtaken samples are the
// slow ones). Each writer's stream is then one sample per ping period, which 20 ms of jitter does
// not reorder, and the figures are those of the radio. The same effect hit Raft's mesh/raft, whose
// RaftRadio (agent/mission) now also spreads its messages over several writers per member.
//
// Pings and pongs share one topic (like Raft's); a sample is for us when `to == self`. A ping from
// anyone (a peer, a ground station) is answered; a pong is counted only from a peer we pinged.
// Our own samples come back on our reader and are ignored.
//
// Thread-safety: Poll() from one thread. A mutex guards the LinkMonitor between Poll(), the
// sender thread and the subscriber callback. Destroying the link stops and joins the sender and
// waits for a running callback. Ownership: the publisher/subscriber share the participant's
// middleware objects (they may outlive the Participant object, see participant.hpp); destroy the
// link before the participant anyway.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "swarmbox/bus/participant.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/radio/link_event.hpp"
#include "swarmbox/radio/link_monitor.hpp"

namespace swarmbox::radio {

struct RadioLinkOptions {
  std::chrono::milliseconds ping_every{200};     // per peer (the agent's --ping-every-ms), > 0
  std::chrono::milliseconds timeout{1000};       // a ping unanswered this long is lost, > 0
  std::chrono::milliseconds report_every{2000};  // one event=link line per peer per window, > 0
};

class RadioLink {
 public:
  struct Counters {
    std::uint64_t pings_sent = 0;      // handed to the publisher (failures also in send_errors)
    std::uint64_t send_errors = 0;     // Publish() failures (the ping then counts as lost)
    std::uint64_t pings_answered = 0;  // pongs we published for others' pings
    std::uint64_t pongs_received = 0;  // pongs addressed to us (any outcome)
    std::uint64_t ignored = 0;         // samples for others, our own, or refused pongs
  };

  // `peers` may contain `self` (e.g. the trial's member list): it is dropped, as are repeats.
  // kInvalidArgument for a bad drone name (self or a peer, bus::ValidateDroneName), non-positive
  // options, or no peer left; the bus errors of creating the writer or reader otherwise.
  static Result<std::unique_ptr<RadioLink>> Create(bus::Participant& mesh, std::string self,
                                                   std::vector<std::string> peers,
                                                   RadioLinkOptions options = {});
  ~RadioLink();
  RadioLink(const RadioLink&) = delete;
  RadioLink& operator=(const RadioLink&) = delete;

  // When a report window has ended by `now` (wall clock): its link lines stamped with `sim_t_s`;
  // usually none. Allocates only when a window ends.
  std::vector<LogEvent> Poll(std::chrono::steady_clock::time_point now, double sim_t_s);

  Counters counters() const;
  const std::string& self() const { return self_; }
  const std::vector<std::string>& peers() const { return monitor_.peers(); }

 private:
  struct PongRequest {
    std::string to;
    std::uint64_t seq = 0;
    std::int64_t sent_wall_ns = 0;
  };

  RadioLink(std::string self, std::vector<std::string> peers, RadioLinkOptions options);
  void OnSample(const bus::RadioPing& m);
  void SenderLoop();
  void Publish(bus::Publisher<bus::RadioPing>& writer, const bus::RadioPing& m);
  bus::Publisher<bus::RadioPing>& PongWriter(const std::string& to);

  std::string self_;
  std::mutex mu_;  // guards monitor_, pong_queue_, stop_
  std::condition_variable wake_;
  LinkMonitor monitor_;
  std::vector<PongRequest> pong_queue_;  // pings to answer, filled by the callback
  bool stop_ = false;
  std::atomic<std::uint64_t> pings_sent_{0};
  std::atomic<std::uint64_t> send_errors_{0};
  std::atomic<std::uint64_t> pings_answered_{0};
  std::atomic<std::uint64_t> pongs_received_{0};
  std::atomic<std::uint64_t> ignored_{0};
  // Per peer (peers() order): the pings to it, the pongs to it; pongs to anyone else.
  std::vector<std::unique_ptr<bus::Publisher<bus::RadioPing>>> ping_writers_;
  std::vector<std::unique_ptr<bus::Publisher<bus::RadioPing>>> pong_writers_;
  std::unique_ptr<bus::Publisher<bus::RadioPing>> other_pong_writer_;
  std::unique_ptr<bus::Subscriber<bus::RadioPing>> subscriber_;
  std::thread sender_;  // started last in Create, stopped first in the destructor
};

}  // namespace swarmbox::radio
