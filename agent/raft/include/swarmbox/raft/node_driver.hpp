// NodeDriver: one drone's Raft node wired to its storage, radio and replicated state machine.
//
// The transport-facing shell around the pure RawNode (raw_node.hpp). It owns the RawNode and the
// StateMachine it replicates (state_machine.hpp: MissionStateMachine by default, EntryLogMachine,
// or the caller's); the caller owns the clock, the radio and the disk, behind three small
// interfaces (real ones in the agent, fakes in tests and in the cluster simulator):
//   Transport  Send(to_name, bytes): best effort, one datagram per message (Raft retries; the
//              transport must not retransmit or hide loss, e.g. a best-effort DDS writer on the
//              mesh radio topic, addressed by drone name);
//   Storage    durable state (WalStorage in the agent);
//   Clock      NowS(): the `t` of log events (the agent's simulated seconds).
// Events are handed to the caller's sink as LogEvents (the logfmt contract):
//   event=leader_elected term=3 leader=drone_2     every node, when it learns of a new leader
//   event=raft_stopped reason="..."                storage failed: the node is dead (exit!)
//   event=raft_conf_change op=remove node=scout_3 voters=scout_1,scout_2,scout_4,scout_5 learners=95
//                                                  every node, when it applies a membership change
//                                                  (op: add_learner | promote | remove)
// plus the state machine's own lines, written while it applies an entry (MissionStateMachine:
// event=mission_state, victim_confirmed, victim_status; mission_state_machine.hpp).
//
// The committed-entries tap: TakeCommitted(&v) replaces v with every application entry (no-ops
// left out) applied since the previous call, {index, data} in index order, on every node (the
// proposer's own included). Open() fills it with the replay of what the node already holds, so a
// new reader (a brain object or process started with the node) sees the whole log again:
//   - a restored snapshot (storage at Open, or one the leader sent) yields what the machine's
//     ReplayRestored() gives for it: EntryLogMachine every entry it holds above what was applied
//     before; MissionStateMachine and machines without a replay nothing (the restored state
//     stands for those entries);
//   - then the committed entries after the snapshot, re-applied from the log, one by one.
// Within one driver the tap never yields an index twice nor goes back. The tap keeps everything
// until taken; a node whose application reads only the machine's state sets
// DriverConfig::tap_committed = false (TakeCommitted then yields nothing, nothing is kept).
//
// Usage (the agent's Raft thread, or its event loop; the driver is not thread-safe):
//
//   DriverConfig cfg;
//   cfg.self = "scout_1";
//   cfg.members = {"scout_1", "scout_2", "lifter"};   // same list on every drone (order free)
//   cfg.seed = trial_seed;                            // the trial's seed, any value per drone
//   ReadRaftOptions(trial_raft_mapping, &cfg);        // timings per trial (raft_options.hpp)
//   auto wal = WalStorage::Open(fs, "/var/lib/swarmbox/raft");
//   auto node = NodeDriver::Open(cfg, **wal, radio, clock, [](const LogEvent& e) {
//     std::puts(e.str().c_str());
//   });
//   if (!node) { print node.error(); exit(1); }
//   every cfg.tick_ms of the caller's clock: (*node)->Tick();    // raft_service::RaftService does this
//   on a radio sample addressed to self:    (*node)->Receive(bytes);   // errors: log, go on
//   to change the mission:                  (*node)->Propose(StartSearch{});  // kUnavailable:
//                                                     // no leader yet, retry later
//   read the agreed mission:                (*node)->mission().phase() ...
//   any other machine:   NodeDriver::Open(cfg, wal, radio, clock, sink,
//                                         std::make_unique<EntryLogMachine>());
//                        (*node)->Propose(Bytes{...});   (*node)->TakeCommitted(&entries);
// Any call returns the storage error once the node has stopped (stopped() is true): the agent
// must then exit non-zero, since it can no longer promise what it voted or acknowledged.
//
// Swarm scale (conf_change.hpp, raw_node.hpp "Learners"): DriverConfig::voters names the starting
// voting set (the trial's first V drones, the same list on every drone); every other member is a
// learner. Empty, or every member: everyone votes and nothing below happens (as before learners
// existed). With learners, the leader runs the lost-voter replacement policy after every tick, one
// membership change at a time (each waits until the previous one is applied):
//   1. a voter that has not answered for voter_lost_ms (default 3 x the election timeout, on the
//      caller's clock) is removed (RemoveNode);
//   2. while there are fewer voters than at the start, the learner with the highest match index
//      that answered within the last 2 x learner_heartbeat_ms is promoted (PromoteLearner);
//   3. a member of the trial in neither set (a removed voter) is added back as a learner
//      (AddLearner), so it follows the log again when it returns.
// A new leader knows nobody's history: its clocks for 1 and 2 start at its election.
//
// Timing defaults (radio: 100 ms +- 20 ms one-way delay, 5% loss): tick 50 ms, heartbeat 100 ms
// (about half the round trip), election timeout 500 ms randomised to [500, 1000) ms (5x the
// heartbeat: a follower only times out after ~5 heartbeats in a row are lost, and even then
// PreVote and the CheckQuorum lease keep it from deposing a healthy leader). etcd's rule of
// thumb (election ~ 10x a heartbeat of ~ one round trip, i.e. ~2 s here) would put failover
// above 2 s; measured with these defaults (swarmbox-bench raft): failover after a leader crash
// p50 ~1.05 s, p99 ~1.6 s, no spurious elections. Candidates re-send unanswered (pre-)vote
// requests every 2 heartbeats (Raft §5.1 "servers retry RPCs"), so one lost datagram does not
// cost a whole election round.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/mission_command.hpp"
#include "swarmbox/raft/mission_state.hpp"
#include "swarmbox/raft/mission_state_machine.hpp"
#include "swarmbox/raft/raw_node.hpp"
#include "swarmbox/raft/state_machine.hpp"
#include "swarmbox/raft/storage.hpp"

namespace swarmbox::raft {

class Transport {
 public:
  virtual ~Transport() = default;
  // Best effort: may drop, delay, duplicate or reorder; never blocks for long.
  virtual void Send(const std::string& to, std::span<const std::uint8_t> bytes) = 0;
};

class Clock {
 public:
  virtual ~Clock() = default;
  virtual double NowS() const = 0;  // [s], for event timestamps only
};

struct DriverConfig {
  std::string self;
  std::vector<std::string> members;  // every drone of the cluster, including self
  // The starting voters, a subset of members (same list on every drone); the others are learners.
  // Empty: every member votes.
  std::vector<std::string> voters;
  int learner_heartbeat_ms = 1000;   // the leader serves each learner once per this [ms]
  int voter_lost_ms = 0;             // replace a voter silent this long [ms]; 0: 3 x election
  int tick_ms = 50;                  // how often the caller calls Tick() [ms]
  int heartbeat_ms = 100;            // multiple of tick_ms
  int election_timeout_ms = 500;     // multiple of tick_ms, > heartbeat_ms
  bool pre_vote = true;
  bool check_quorum = true;
  std::uint64_t seed = 1;
  std::uint64_t snapshot_every_entries = 64;  // compact the log after this many applied entries
  std::size_t max_entries_per_msg = 64;
  bool tap_committed = true;  // keep applied entries for TakeCommitted (see the banner)

  // The RawNode config this gives (ids are 1 + the position in the sorted member list), or
  // kInvalidArgument naming the problem.
  Result<Config> ToRaftConfig() const;
  // The timing and tuning fields alone (what a trial may set, see raft_options.hpp).
  Status ValidateTiming() const;
};

class NodeDriver {
 public:
  // Loads `storage`, restores the state machine from its snapshot and rejoins with the stored
  // term, vote and log (re-applying the committed entries after the snapshot, events included).
  // `machine` null: a MissionStateMachine. The references must outlive the driver. Errors: a bad
  // config (kInvalidArgument), unreadable storage, a snapshot the machine cannot restore.
  static Result<std::unique_ptr<NodeDriver>> Open(const DriverConfig& config, Storage& storage,
                                                  Transport& transport, const Clock& clock,
                                                  EventSink sink,
                                                  std::unique_ptr<StateMachine> machine);
  // The same with a MissionStateMachine.
  static Result<std::unique_ptr<NodeDriver>> Open(const DriverConfig& config, Storage& storage,
                                                  Transport& transport, const Clock& clock,
                                                  EventSink sink);

  Status Tick();
  // Bytes received from the radio. kProtocol for undecodable or misaddressed data (the node goes
  // on); the stop error when stopped.
  Status Receive(std::span<const std::uint8_t> bytes);
  // Proposes an entry for the state machine (forwarded to the leader when a follower). Accepted
  // is not committed: a leader change can lose it; watch the tap (or the state) and re-propose.
  // kUnavailable: no leader known (retry later); kInvalidArgument: empty `data` (empty entries
  // are the leader's no-ops); the stop error once stopped.
  Status Propose(Bytes data);
  // The same for an encoded MissionCommand (for a MissionStateMachine).
  Status Propose(const MissionCommand& command);
  Status Campaign();  // start an election now
  // Leader only: proposes a membership change (RawNode::ProposeConfChange: kUnavailable while one
  // is in flight or when not leader; kInvalidArgument when it does not apply).
  Status ProposeConfChange(ConfChangeOp op, const std::string& node);

  // Replaces *out with the application entries applied since the previous call (see the banner).
  void TakeCommitted(std::vector<Committed>* out);

  bool stopped() const { return stop_error_.has_value(); }
  const std::optional<Error>& stop_error() const { return stop_error_; }
  const StateMachine& machine() const { return *machine_; }
  // The MissionStateMachine's mission; nullptr when the machine is another kind.
  const MissionState* FindMission() const {
    return mission_machine_ != nullptr ? &mission_machine_->mission() : nullptr;
  }
  // The mission of a MissionStateMachine (aborts for another machine: a programming error).
  const MissionState& mission() const;
  std::uint64_t applied_index() const { return applied_; }  // the machine's last index
  const RawNode& raft() const { return node_; }
  const std::string& self() const { return config_.self; }
  std::string leader() const;  // the known leader's name, "" when none
  bool is_leader() const { return node_.role() == Role::kLeader; }
  const std::string& NameOf(NodeId id) const { return names_[id - 1]; }
  // The configuration this driver has applied (the same as raft().conf_state() between calls).
  const ConfState& conf_state() const { return node_.conf_state(); }
  NodeId IdOf(const std::string& name) const;  // kNoNode when not a member

 private:
  NodeDriver(DriverConfig config, std::vector<std::string> names, std::uint32_t tag, RawNode node,
             std::unique_ptr<StateMachine> machine, std::uint64_t applied,
             std::vector<Committed> tap, Storage& storage, Transport& transport,
             const Clock& clock, EventSink sink);
  // Hands every Ready over (persist, send, announce, install, apply, advance), then compacts.
  Status Process();
  void AnnounceLeader(const std::optional<SoftState>& soft_state);  // event=leader_elected once per term
  Status InstallSnapshot(const Snapshot& snapshot);  // the leader's, as a Ready delivers it
  Status CompactIfDue();
  Status Stop(Error e);
  void Emit(const LogEvent& e) const;
  void ApplyEntry(const Entry& e);
  void ApplyConfEntry(const Entry& e);
  Status ReplaceLostVoters();  // the leader's policy (see the banner)
  std::string NameOrId(NodeId id) const;

  DriverConfig config_;
  std::vector<std::string> names_;  // sorted; id = index + 1
  std::uint32_t cluster_tag_;
  RawNode node_;
  std::unique_ptr<StateMachine> machine_;
  const MissionStateMachine* mission_machine_;  // machine_ when it is one, else nullptr
  std::uint64_t applied_;                       // last index applied to (or restored into) machine_
  std::vector<Committed> tap_;                  // applied since the last TakeCommitted
  Storage& storage_;
  Transport& transport_;
  const Clock& clock_;
  EventSink sink_;
  std::optional<Error> stop_error_;
  NodeId announced_lead_ = kNoNode;
  std::uint64_t announced_term_ = 0;
  ConfState conf_applied_;          // the membership as of applied_ (for the change events)
  std::size_t target_voters_ = 0;   // > 0: replace lost voters up to this many (learners exist)
};

}  // namespace swarmbox::raft
