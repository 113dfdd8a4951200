// RaftHost: the agent's Raft node (agent/raft_service's passive RaftService) driven by the control
// loop on the radio's clock, its messages carried by the agent's MeshRadio, plus the storage
// failure check and a diagnostic proposal loop.
//
// The swarm agrees on its mission through Raft (agent/raft). The service has no thread and no
// bus: every lockstep step the node hands it the Raft payloads the radio delivered (OnPayload,
// in delivery order), then calls Step(), which runs the ticks due by the Raft clock and, with
// propose_every_ms > 0, proposes the next demo mission command (raft_service/demo_mission.hpp) when
// this node leads. Its messages go out as RadioFrames (raft_msg: one RaftMessage {from, to, term,
// payload}) through radio.Send, inside those calls.
//
//   RadioClock clock(*radio, 0);                       // channel: simulated seconds
//   RadioClock clock(*radio, radio->now_ns());         // netem: wall seconds since start
//   auto host = RaftHost::Start(options, *radio, clock, stdout, &sim_clock);
//   for (payload delivered this step) host->OnPayload(payload);
//   if (Status s = host->Step(); !s) exit(1);           // storage failed
//
// Clocks: `clock` times Raft (ticks, heartbeats, election timeouts, the proposal loop):
// RadioClock over the radio's now_ns, i.e. the lockstep's simulated time with radio.model channel
// and the steady clock with netem. The event lines (event=leader_elected, ...) carry `t` from
// `event_clock` when given (the agent's simulated seconds, so that every line of an agent is on one
// axis in both models), else from `clock`.
// Swarm scale: options.voters (--raft-voters) is the voting set; the other members are learners
// that follow the log and forward their proposals (agent/raft/README.md "Swarm scale").
// The replicated state machine is the caller's (`machine` at Start; null: a MissionStateMachine,
// the SAR mission, read through mission(); --mission sar hands it SarBrain's own). A brain reads the
// committed log through TakeCommitted (every entry applied since the previous call, in index
// order; after a restart first the replay of the WAL, see raft/node_driver.hpp) and proposes
// bytes with ProposeBytes.
//
// Thread-safety: none; the control loop calls everything. Ownership: `radio`, `clock`,
// `event_clock` and `log` must outlive the host.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/raft_service/raft_service.hpp"
#include "swarmbox/radio/mesh_radio.hpp"
#include "swarmbox/raft/file_system.hpp"
#include "swarmbox/raft/node_driver.hpp"
#include "swarmbox/raft/state_machine.hpp"

namespace swarmbox::agent {

struct RaftHostOptions {
  std::string self;                  // this drone's name
  std::vector<std::string> members;  // every drone of the trial, including self, same on all
  std::vector<std::string> voters;   // the voting set (a subset of members); empty: all vote
  std::string raft_dir;              // WAL and snapshot directory (created when missing)
  std::uint64_t seed = 1;            // the trial's seed
  int tick_ms = 50;                  // Raft tick on the radio's clock [ms]
  int heartbeat_ms = 100;            // multiple of tick_ms [ms]
  int election_timeout_ms = 500;     // multiple of tick_ms, > heartbeat_ms [ms]
  int propose_every_ms = 0;          // 0: never; N: the leader proposes a demo command every N ms
  raft::FileSystem* file_system = nullptr;  // the WAL's; nullptr = the real one (tests inject)
};

// "a,b,c" -> {"a","b","c"}; kInvalidArgument for an empty item, a bad drone name, a duplicate, or
// a list without `self`.
Result<std::vector<std::string>> ParseMembers(std::string_view text, std::string_view self);

// "a,b" -> {"a","b"}: the voting set, each a member, none twice; kInvalidArgument otherwise.
Result<std::vector<std::string>> ParseVoters(std::string_view text, const std::vector<std::string>& members);

// The default WAL directory of a drone: /tmp/swarmbox-raft/<name> (survives an agent restart on
// the same machine or container; give --raft-dir a volume to survive the container).
std::string DefaultRaftDir(std::string_view name);

// The agent's simulated seconds as a raft::Clock (set by the control loop).
class SimClock final : public raft::Clock {
 public:
  double NowS() const override { return t_s_; }
  void Set(double t_s) { t_s_ = t_s; }

 private:
  double t_s_ = 0.0;
};

// A MeshRadio's clock (now_ns) as a raft::Clock, in seconds since `origin_ns` on that clock.
class RadioClock final : public raft::Clock {
 public:
  RadioClock(const radio::MeshRadio& radio, std::int64_t origin_ns) : radio_(radio), origin_ns_(origin_ns) {}
  double NowS() const override { return static_cast<double>(radio_.now_ns() - origin_ns_) * 1e-9; }

 private:
  const radio::MeshRadio& radio_;
  std::int64_t origin_ns_;
};

// raft::Transport onto a MeshRadio: Send(to, bytes) is one frame to `to` carrying one
// RaftMessage {from = self, to, term (peeked from the bytes), payload}.
class RadioTransport final : public raft::Transport {
 public:
  RadioTransport(radio::MeshRadio& radio, std::string self) : radio_(radio), self_(std::move(self)) {}
  void Send(const std::string& to, std::span<const std::uint8_t> bytes) override;

 private:
  radio::MeshRadio& radio_;
  std::string self_;
};

class RaftHost {
 public:
  // Opens the WAL (replaying it into `machine`, null: a MissionStateMachine) and starts the
  // service; events are logfmt lines on `log`. Errors: kInvalidArgument for bad members/timings
  // or propose_every_ms > 0 with a machine other than the mission, the storage's errors.
  static Result<std::unique_ptr<RaftHost>> Start(const RaftHostOptions& options, radio::MeshRadio& radio,
                                                 const raft::Clock& clock, std::FILE* log,
                                                 const raft::Clock* event_clock = nullptr,
                                                 std::unique_ptr<raft::StateMachine> machine = nullptr);

  // A delivered RaftMessage payload addressed to this drone, in delivery order.
  void OnPayload(std::span<const std::uint8_t> bytes) { service_->OnPayload(bytes); }
  // The ticks due by the clock, then the proposal loop. Ok while running; the service's stop
  // error (storage failed) once it stopped, on every later call.
  Status Step();
  bool stopped() const { return service_->stopped(); }
  raft_service::RaftService& service() { return *service_; }

  // The committed-entries tap: replaces *out with the entries applied since the previous call.
  void TakeCommitted(std::vector<raft::Committed>* out) { service_->TakeCommitted(out); }
  // Proposes an entry (kUnavailable: no leader known; kInvalidArgument: empty; the stop error).
  Status ProposeBytes(raft::Bytes data) { return service_->ProposeBytes(std::move(data)); }
  std::string leader() const { return service_->leader(); }  // "" when none known
  bool is_leader() const { return service_->is_leader(); }
  const raft::StateMachine& machine() const { return service_->machine(); }
  // The committed SAR mission (a MissionStateMachine only; aborts otherwise). FindMission():
  // nullptr for another machine.
  const raft::MissionState& mission() const { return service_->mission(); }
  const raft::MissionState* FindMission() const { return service_->FindMission(); }

 private:
  RaftHost(RaftHostOptions options, radio::MeshRadio& radio, const raft::Clock& clock)
      : options_(std::move(options)), transport_(radio, options_.self), clock_(clock) {}

  RaftHostOptions options_;
  RadioTransport transport_;  // before service_: outlives it
  const raft::Clock& clock_;
  std::unique_ptr<raft_service::RaftService> service_;
  double next_propose_s_ = 0.0;
};

// `line` with its leading "t=<number>" replaced by `t_s` (3 decimals); unchanged without one.
std::string RestampLine(std::string_view line, double t_s);

}  // namespace swarmbox::agent
