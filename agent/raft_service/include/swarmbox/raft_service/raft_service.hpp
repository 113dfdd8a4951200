// RaftService: one drone's Raft node, driven by its caller's loop on the caller's clock.
//
// Owns a raft::NodeDriver (node_driver.hpp) and its WalStorage in `data_dir`. It has no thread
// and no bus: the caller hands it the received Raft payloads (OnPayload) and calls Tick() on its
// loop; the node's messages go out through the caller's raft::Transport, synchronously inside
// these calls. Time is the caller's raft::Clock: the agent's simulated seconds (radio model
// `channel`), or a monotonic clock (radio model `netem`, swarmbox-raft-node). The same sequence
// of calls with the same clock readings gives the same messages and the same event lines.
//
//   RaftServiceConfig cfg;
//   cfg.driver.self = "scout_1";
//   cfg.driver.members = {"scout_1", "scout_2", "lifter"};  // the trial's drones, on every drone
//   cfg.driver.seed = trial_seed;
//   ReadRaftOptions(trial_raft_mapping, &cfg.driver);       // per-trial timings (optional)
//   cfg.data_dir = "/var/lib/swarmbox/raft";
//   auto raft = RaftService::Start(cfg, transport, sim_clock);   // prints events on stdout
//   if (!raft) { print raft.error(); exit(1); }
//   every control step, at simulated time t_k (the clock reads t_k):
//     for (payload : raft payloads delivered this step, in delivery order) (*raft)->OnPayload(payload);
//     if (Status s = (*raft)->Tick(); !s) exit(1);   // storage failed: the node must die loudly
//     (*raft)->Propose(raft::StartSearch{});         // kUnavailable: no leader known, retry later
//     raft::MissionState m = (*raft)->mission();     // a copy of the committed mission
//
// Any other replicated state: hand Start() the machine (raft/state_machine.hpp), propose bytes and
// read the committed entries from the tap:
//   auto raft = RaftService::Start(cfg, transport, sim_clock, sink,
//                                  std::make_unique<raft::EntryLogMachine>());
//   (*raft)->ProposeBytes(bytes);
//   (*raft)->TakeCommitted(&entries);   // since the previous call, in index order, replay first
//
// Ticks: Tick() runs the driver's ticks due by clock.NowS() on a fixed grid, start + n * tick_ms,
// where `start` is the clock at Start() (read in whole microseconds, so float noise in the clock
// cannot move a tick across a step). Calling Tick() more often than every tick_ms is free (it
// runs none); a call late by up to max_catch_up_ticks() ticks runs every tick it owes. A longer
// gap (the process was paused or stopped, the drone was out of the lockstep, the machine stalled)
// runs max_catch_up_ticks() ticks and drops the rest (dropped_ticks()), then goes on on the same
// grid: the node heard nothing during the gap, and replaying all of its ticks at once, without
// the messages that would have come between them, would fire every timer together and send a
// burst of stale (pre-)votes. Dropping missed ticks is what a Go time.Ticker does to a slow etcd
// node, and what the threaded service did before. max_catch_up_ticks() = heartbeat_ms / tick_ms
// (4 with a 50 ms tick and a 200 ms heartbeat): a loop late by less than a heartbeat loses no
// Raft time at all.
//
// Events: the driver's contract events (event=leader_elected, raft_stopped) and the machine's
// (MissionStateMachine: mission_state, victim_confirmed, victim_status) go to `out` as logfmt lines, `t` from the clock given, during
// the call that caused them. Received bytes the driver cannot decode are counted
// (protocol_errors()), not fatal.
//
// Failure: when the driver stops (a storage write or fsync failed: it can no longer promise what
// it voted or acknowledged) it prints event=raft_stopped; from then on health(), Tick(),
// Propose() and Campaign() return that error and OnPayload() drops its bytes. The caller must
// then exit non-zero.
//
// Thread-safety: none. One thread (the control loop) calls everything, `out` and the
// transport's Send included (they run inside the calls). Payloads received on other threads
// (RaftRadio's middleware callback) go through a PayloadInbox (payload_inbox.hpp) and are fed at
// the next step. Ownership: `transport` and `clock` must outlive the service; the destructor
// closes the storage.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/file_system.hpp"
#include "swarmbox/raft/mission_state.hpp"
#include "swarmbox/raft/node_driver.hpp"
#include "swarmbox/raft/state_machine.hpp"
#include "swarmbox/raft/wal_storage.hpp"

namespace swarmbox::raft_service {

struct RaftServiceConfig {
  raft::DriverConfig driver;  // self, members, seed, timings (tick_ms: the Tick() grid)
  std::string data_dir;       // WAL and snapshot directory, created when missing
  // The file system of the WAL; nullptr = the real one (PosixFileSystem). Tests inject failures.
  // Must outlive the service.
  raft::FileSystem* file_system = nullptr;
};

// One logfmt line per call, without a trailing newline.
using LineSink = std::function<void(const std::string& line)>;
// Writes the line and '\n' to stdout and flushes.
void PrintLineToStdout(const std::string& line);

class RaftService {
 public:
  // Opens the storage (replaying the WAL: re-applied entries print their events now and fill the
  // committed-entries tap) and the driver with `machine` (null: a MissionStateMachine); reads
  // `clock` once to anchor the tick grid. Errors: a bad DriverConfig or no data directory
  // (kInvalidArgument), storage that cannot be read or restored (kIo/kProtocol).
  static Result<std::unique_ptr<RaftService>> Start(const RaftServiceConfig& config,
                                                    raft::Transport& transport,
                                                    const raft::Clock& clock,
                                                    LineSink out = PrintLineToStdout,
                                                    std::unique_ptr<raft::StateMachine> machine = nullptr);
  ~RaftService();
  RaftService(const RaftService&) = delete;
  RaftService& operator=(const RaftService&) = delete;

  // A delivered Raft payload (RaftMessage.payload addressed to self), in delivery order. Bytes
  // the driver refuses are counted in protocol_errors(); dropped once stopped.
  void OnPayload(std::span<const std::uint8_t> bytes);
  // Runs the ticks due by clock.NowS() (see the banner). Ok while running; the stop error once
  // the node stopped.
  Status Tick();
  // Proposes a mission command (encoded by the driver). kUnavailable when this node knows no
  // leader to forward to; the stop error once stopped.
  Status Propose(const raft::MissionCommand& command);
  // Proposes an entry for the machine (NodeDriver::Propose(Bytes)): kUnavailable when no leader
  // is known, kInvalidArgument for empty bytes, the stop error once stopped.
  Status ProposeBytes(raft::Bytes data);
  // Starts an election now (tests, the "kill the leader" fault's bookkeeping).
  Status Campaign();
  // Replaces *out with the entries applied since the previous call (NodeDriver::TakeCommitted).
  void TakeCommitted(std::vector<raft::Committed>* out) { driver_->TakeCommitted(out); }

  const raft::StateMachine& machine() const { return driver_->machine(); }
  // The committed mission of a MissionStateMachine (aborts for another machine); FindMission():
  // nullptr then.
  const raft::MissionState& mission() const { return driver_->mission(); }
  const raft::MissionState* FindMission() const { return driver_->FindMission(); }
  std::uint64_t applied_index() const { return driver_->applied_index(); }
  std::string leader() const { return driver_->leader(); }  // "" when none known
  bool is_leader() const { return driver_->is_leader(); }
  std::uint64_t term() const { return driver_->raft().term(); }
  raft::Role role() const { return driver_->raft().role(); }
  bool is_learner() const { return driver_->raft().is_learner(); }
  std::uint64_t commit_index() const { return driver_->raft().log().committed(); }

  // Ok while running; the driver's stop error once it stopped (storage failed: exit non-zero).
  Status health() const;
  bool stopped() const { return driver_->stopped(); }

  std::uint64_t protocol_errors() const { return protocol_errors_; }  // undecodable payloads
  std::uint64_t ticks() const { return ticks_; }                 // driver ticks run
  std::uint64_t dropped_ticks() const { return dropped_ticks_; }  // ticks skipped after a gap
  int max_catch_up_ticks() const { return max_catch_up_ticks_; }
  // The clock time [s] at which the next tick is due (a loop may sleep until then).
  double next_tick_s() const;
  const std::string& self() const { return config_.driver.self; }

 private:
  RaftService(RaftServiceConfig config, const raft::Clock& clock, LineSink out);

  RaftServiceConfig config_;
  const raft::Clock& clock_;
  LineSink out_;
  std::unique_ptr<raft::FileSystem> own_fs_;  // when config_.file_system is null
  std::unique_ptr<raft::WalStorage> wal_;
  std::unique_ptr<raft::NodeDriver> driver_;  // after wal_: destroyed before it

  std::int64_t tick_us_ = 0;       // config_.driver.tick_ms in [us]
  std::int64_t next_tick_us_ = 0;  // clock time of the next tick on the grid [us]
  int max_catch_up_ticks_ = 1;
  std::uint64_t ticks_ = 0;
  std::uint64_t dropped_ticks_ = 0;
  std::uint64_t protocol_errors_ = 0;
};

}  // namespace swarmbox::raft_service
