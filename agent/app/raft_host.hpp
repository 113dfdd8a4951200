// RaftHost: the agent's Raft node on the mesh radio (agent/mission RaftService), with the
// agent's simulated time as the event clock and a diagnostic proposal loop.
//
// The swarm agrees on its mission through Raft (agent/raft); RaftService runs the node on its own
// thread over the agent's mesh bus::Participant. RaftHost adds what the agent needs around it:
//   - SimClock: the agent's simulated seconds (set by the control loop, read by the service
//     thread), so raft events carry the same `t` as the flight events;
//   - Poll(): called from the control loop; reports a stopped service (storage failed: the agent
//     must exit 1) and, with propose_every_ms > 0, proposes the next demo mission command
//     (mission/demo_mission.hpp) when this node leads, until the SAR mission layer replaces it.
//
//   RaftHostOptions r;  r.self = "drone_1";  r.members = {"drone_1", "drone_2", "drone_3"};
//   r.raft_dir = DefaultRaftDir("drone_1");  r.seed = 7;  r.propose_every_ms = 300;
//   auto host = RaftHost::Start(r, *mesh, stdout);   // kInvalidArgument: bad members/timings
//   host->SetSimTime(t_s);                           // control loop, every sample
//   if (Status s = host->Poll(); !s) exit(1);        // storage failed
//
// Thread-safety: SetSimTime/Poll from one thread (the control loop); the clock is atomic.
// Ownership: `mesh` and `log` must outlive the host; destroy the host before the participant.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/bus/participant.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/mission/raft_service.hpp"
#include "swarmbox/raft/file_system.hpp"
#include "swarmbox/raft/node_driver.hpp"

namespace swarmbox::agent {

struct RaftHostOptions {
  std::string self;                  // this drone's name
  std::vector<std::string> members;  // every drone of the trial, including self, same on all
  std::string raft_dir;              // WAL and snapshot directory (created when missing)
  std::uint64_t seed = 1;            // the trial's seed
  int tick_ms = 50;                  // wall-clock tick of the service thread [ms]
  int heartbeat_ms = 100;            // multiple of tick_ms [ms]
  int election_timeout_ms = 500;     // multiple of tick_ms, > heartbeat_ms [ms]
  int propose_every_ms = 0;          // 0: never; N: the leader proposes a demo command every N ms
  raft::FileSystem* file_system = nullptr;  // the WAL's; nullptr = the real one (tests inject)
};

// "a,b,c" -> {"a","b","c"}; kInvalidArgument for an empty item, a bad drone name, a duplicate, or
// a list without `self`.
Result<std::vector<std::string>> ParseMembers(std::string_view text, std::string_view self);

// The default WAL directory of a drone: /tmp/swarmbox-raft/<name> (survives an agent restart on
// the same machine or container; give --raft-dir a volume to survive the container).
std::string DefaultRaftDir(std::string_view name);

// The agent's simulated seconds as a raft::Clock (written by the control loop, read by the
// service thread).
class SimClock final : public raft::Clock {
 public:
  double NowS() const override { return t_s_.load(std::memory_order_relaxed); }
  void Set(double t_s) { t_s_.store(t_s, std::memory_order_relaxed); }

 private:
  std::atomic<double> t_s_{0.0};
};

class RaftHost {
 public:
  // Opens the WAL (replaying it) and starts the service on `mesh`; events are logfmt lines on
  // `log`. Errors: kInvalidArgument for bad members/timings, the storage's or the bus's errors.
  static Result<std::unique_ptr<RaftHost>> Start(const RaftHostOptions& options, bus::Participant& mesh,
                                                 std::FILE* log);
  ~RaftHost() = default;  // stops the service (thread, radio, storage)

  void SetSimTime(double t_s) { clock_.Set(t_s); }
  // Cheap when called often (looks at the service at most every 20 ms of wall-clock time). Ok
  // while running; the service's stop error (storage failed) once it stopped, on every later call.
  Status Poll();
  bool stopped() const { return stopped_; }
  mission::RaftService& service() { return *service_; }

 private:
  explicit RaftHost(RaftHostOptions options) : options_(std::move(options)) {}

  RaftHostOptions options_;
  SimClock clock_;                                 // before service_: outlives it
  std::unique_ptr<mission::RaftService> service_;  // destroyed first
  std::chrono::steady_clock::time_point next_poll_{};
  std::chrono::steady_clock::time_point next_propose_{};
  bool stopped_ = false;
};

}  // namespace swarmbox::agent
