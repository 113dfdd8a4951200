// ClusterSim: a deterministic discrete-event simulator of a Raft cluster of NodeDrivers.
//
// Time is simulated (microseconds); one seed drives every random choice: message delay and
// jitter, loss, duplication, reordering, partitions, crashes and restarts (storage kept, as a
// MemoryStorage), tick phases and proposals. Messages go through the real codec and the real
// driver, so the simulator exercises everything but files and sockets.
//
// After every step (a tick, a delivery, a proposal, a restart) it checks the Raft safety
// properties (Raft §5.2 Figure 3):
//   Election Safety      at most one leader per term; a node votes once per term
//   Leader Append-Only   a leader's storage writes only append (never overwrite or truncate)
//   Log Matching         two entries with the same index and term hold the same data and follow
//                        entries of the same term (checked on every storage write)
//   Leader Completeness  a new leader holds every entry committed before its election
//   State Machine Safety every node's state machine after applying index i is the same (its
//                        Snapshot() bytes), and nodes commit the same entry at each index
// plus, for membership (conf_change.hpp):
//   Configuration        every node has the same configuration after applying index i; no
//                        committed change fails to apply; a leader is a voter of its configuration
//   One Change at a Time a leader appends a change only when no other change is in its log above
//                        its applied index, and only after it applied an entry of its own term
//   Commit Quorum        when an index is first committed, a majority of the committing leader's
//                        voters hold it in durable storage (learners never make a quorum)
// plus monotonic terms, and the committed-entries tap (NodeDriver::TakeCommitted, drained after
// every step): per node life it yields committed entries only, with the committed data, in
// strictly increasing index order; with the EntryLogMachine also every one of them from index 1
// on (after a restart and a snapshot from the leader too: the replay). The machine is
// SimConfig::machine: the mission (MissionStateMachine, the proposals are mission commands) or the
// entry log (EntryLogMachine, the same proposals as opaque bytes). A violation is recorded with the seed and time; the first stops the run.
//
//   SimConfig cfg;                 // 5 nodes, radio-like network, no faults
//   cfg.seed = 42;
//   cfg.faults.crash_mean_interval_s = 5;
//   SimReport r = RunSimulation(cfg);
//   if (!r.ok()) std::puts(r.violations[0].c_str());   // "seed=42 t=12.340 Log Matching: ..."
//
// Swarm scale: SimConfig::voters = V > 0 makes n1..nV the starting voters and every other node a
// learner; the drivers then run the lost-voter replacement policy (node_driver.hpp), and
// conf_change_interval_s > 0 adds random membership changes at the leader on top.
//
// For scripted scenarios drive a ClusterSim directly: RunFor(), Crash(), Restart(),
// Partition(), Heal(), Propose(), ProposeConfChange().
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <queue>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include "swarmbox/raft/node_driver.hpp"
#include "swarmbox/raft/sim/memory_storage.hpp"

namespace swarmbox::raft::sim {

struct NetworkModel {
  double delay_ms = 100;    // mean one-way delay
  double jitter_ms = 20;    // uniform in [-jitter, +jitter]
  double loss = 0.05;       // probability a message is dropped
  double duplicate = 0;     // probability a message is delivered twice (independent delays)
  double reorder = 0;       // probability a message gets an extra delay of up to reorder_ms
  double reorder_ms = 300;
};

struct FaultModel {
  double crash_mean_interval_s = 0;  // mean time between crashes of a random node (0: none)
  double crash_leader_bias = 0.5;    // probability that a crash hits the current leader
  double down_min_s = 0.5, down_max_s = 4;      // how long a crashed node stays down
  double partition_mean_interval_s = 0;  // mean time between random partitions (0: none)
  double partition_min_s = 0.5, partition_max_s = 5;
  // Breaks Raft's durability assumption on purpose: a restarted node comes back with empty
  // storage. Only for checking that the safety checker catches what follows.
  bool wipe_storage_on_restart = false;
};

enum class SimMachine : std::uint8_t { kMission, kEntryLog };

struct SimConfig {
  int nodes = 5;  // 1..200
  int voters = 0;  // the starting voters n1..nV, the rest learners; 0 (or >= nodes): all vote
  int learner_heartbeat_ms = 1000;
  int voter_lost_ms = 0;  // 0: 3 x election_timeout_ms
  // Random membership changes at the leader (remove a voter or a learner, promote a learner, add
  // a non-member as learner), on top of the replacement policy; 0: none.
  double conf_change_interval_s = 0;
  // Voter-crash schedule (the replacement figure): at each time, crash a live voter that is not
  // the leader; it stays down voter_down_s.
  std::vector<double> voter_crash_at_s;
  double voter_down_s = 30;
  SimMachine machine = SimMachine::kMission;  // every node's replicated state machine
  std::uint64_t seed = 1;
  double duration_s = 20;
  NetworkModel net;
  FaultModel faults;
  int tick_ms = 50;
  int heartbeat_ms = 100;
  int election_timeout_ms = 500;
  bool pre_vote = true;
  bool check_quorum = true;
  std::uint64_t snapshot_every_entries = 32;
  double propose_interval_s = 0.2;  // a random live node proposes a mission command this often
  // Leader-crash schedule (the failover figure): at each time, crash the current leader (if any)
  // and restart it leader_down_s later.
  std::vector<double> leader_crash_at_s;
  double leader_down_s = 3;
  bool record_events = false;  // keep every node's logfmt events in SimReport::events
};

struct SimReport {
  std::uint64_t seed = 0;
  std::vector<std::string> violations;  // "seed=.. t=.. <property>: <details>"
  std::vector<double> failover_ms;      // leader crash -> another node is leader
  int failovers_missed = 0;             // leader crashes with no new leader before the next event
  std::vector<double> commit_ms;        // proposal -> committed (first node to commit it)
  int proposals = 0, proposals_dropped = 0;
  int leader_terms = 0;                 // terms that had a leader
  int leader_crashes = 0, crashes = 0, partitions = 0;
  std::uint64_t messages_sent = 0, messages_delivered = 0;
  std::uint64_t max_commit = 0;
  std::uint64_t snapshots_sent = 0;
  std::vector<std::string> events;  // with record_events
  std::uint64_t entries_tapped = 0;  // entries every node's tap yielded (replays included)
  // Membership.
  int conf_changes = 0;                 // membership changes committed (first commit seen)
  std::vector<double> replacement_ms;   // voter crash -> the leader's configuration has replaced it
  int replacements_missed = 0;          // voter crashes not replaced before the next one / the end
  std::uint64_t leader_messages = 0;    // messages sent by nodes while leading
  int leader_burst_max = 0;             // most messages the leader sent in one step (one tick...)

  bool ok() const { return violations.empty(); }
};

class ClusterSim {
 public:
  explicit ClusterSim(const SimConfig& config);
  ~ClusterSim();
  ClusterSim(const ClusterSim&) = delete;
  ClusterSim& operator=(const ClusterSim&) = delete;

  // Runs events until now + seconds (or the first violation).
  void RunFor(double seconds);
  // Runs until some live node is leader, at most max_s; returns its index or -1.
  int RunUntilLeader(double max_s);

  void Crash(int node);
  void Restart(int node);
  // Nodes in different groups cannot exchange messages (also those already in flight).
  void Partition(const std::vector<std::vector<int>>& groups);
  void Heal();
  Status Propose(int node, const MissionCommand& command);  // encoded
  Status Propose(int node, Bytes data);
  // At `node` (its driver's ProposeConfChange): the change of sim node `target`.
  Status ProposeConfChange(int node, ConfChangeOp op, int target);
  // Drops every message for which the filter returns true (e.g. all vote responses), until
  // cleared with nullptr. Applied at send time.
  using DropFilter = std::function<bool(int from, int to, const Message& m)>;
  void SetDropFilter(DropFilter filter) { drop_filter_ = std::move(filter); }

  double now_s() const { return static_cast<double>(now_us_) / 1e6; }
  int size() const { return static_cast<int>(nodes_.size()); }
  bool alive(int node) const;
  const NodeDriver* driver(int node) const;  // nullptr while crashed
  const MemoryStorage& storage(int node) const;
  // The live leader with the highest term, or -1.
  int Leader() const;
  std::string Name(int node) const { return "n" + std::to_string(node + 1); }
  // The sim node of a Raft id (ids number the sorted names: n1, n10, n100, n11, ...).
  int NodeOf(NodeId id) const { return node_of_id_[static_cast<std::size_t>(id - 1)]; }
  NetworkModel& net() { return config_.net; }

  const SimReport& report() const { return report_; }
  SimReport TakeReport();

 private:
  struct Node;
  struct Event;
  struct EventLater {
    bool operator()(const Event* a, const Event* b) const;
  };
  class NodeTransport;
  class CheckedStorage;
  class SimClock;

  void Schedule(std::int64_t at_us, Event* e);
  void Step();
  void SendMessage(int from, const std::string& to_name, std::span<const std::uint8_t> bytes);
  void ScheduleTick(int node);
  void ScheduleNextCrash();
  void ScheduleNextPartition();
  // Runs `action` again and again, each time after interval_s times U(0.5, 1.5) (the random
  // proposals and configuration changes).
  void ScheduleEvery(double interval_s, void (ClusterSim::*action)());
  void ProposeRandom();
  void CrashLeaderNow();
  void CrashVoterNow();
  void RandomConfChange();
  void CheckCommitQuorum(const RawNode& leader, const ConfState& before, std::uint64_t index, const Entry& e);
  void Violation(const std::string& property, const std::string& details);
  void OnSave(int node, const std::optional<HardState>& hs, std::span<const Entry> entries,
              const Snapshot& snapshot);
  // OnSave's checks: One Change at a Time (thesis §4.1) on a leader's appends, Log Matching
  // (Raft §5.3) on every node's.
  void CheckOneChangeAtATime(int node, const NodeDriver& d, std::span<const Entry> entries);
  void CheckLogMatching(int node, const MemoryStorage& st, std::span<const Entry> entries,
                        const Snapshot& snapshot);
  void CheckNode(int node);
  // The driver configuration of `node` after `restarts` restarts (its seed changes with each).
  DriverConfig DriverConfigOf(int node, int restarts) const;
  // CheckNode's checks, in order: Election Safety of terms and votes (Raft §5.2), State Machine
  // Safety of commits (§5.4.3), a new leader's safety and completeness (§5.2, §5.4), the applied
  // state.
  void CheckTermAndVote(Node& n, const RawNode& raw, const std::string& who);
  void CheckCommits(Node& n, const RawNode& raw, const std::string& who);
  void CheckLeader(Node& n, const RawNode& raw, const std::string& who);
  void CheckLeaderCompleteness(const RawNode& raw, const std::string& who);
  void CheckStateMachine(Node& n, const NodeDriver& d, const std::string& who);
  void CheckTap(int node);
  // The first committed application entry strictly between two indices (0: none seen).
  std::uint64_t SkippedApplication(std::uint64_t after, std::uint64_t before) const;
  double Uniform(double lo, double hi);
  bool Chance(double p);

  SimConfig config_;
  std::mt19937_64 rng_;
  std::int64_t now_us_ = 0;
  std::uint64_t next_seq_ = 0;
  std::priority_queue<Event*, std::vector<Event*>, EventLater> queue_;
  std::vector<std::unique_ptr<Node>> nodes_;
  std::vector<int> group_;
  DropFilter drop_filter_;
  std::uint32_t cluster_tag_ = 0;
  std::unique_ptr<SimClock> clock_;
  SimReport report_;

  // Safety bookkeeping.
  struct EntryFact {
    std::uint64_t prev_term;
    std::uint64_t data_hash;
  };
  struct CommitFact {
    std::uint64_t term;
    std::uint64_t data_hash;
    bool application;  // a kNormal entry (what the tap yields); no-ops and conf changes are not
  };
  std::map<std::uint64_t, NodeId> leader_of_term_;
  std::map<std::pair<std::uint64_t, std::uint64_t>, EntryFact> entries_seen_;  // (index, term)
  std::vector<CommitFact> committed_;  // committed_[i - 1] for index i (term 0: not seen yet)
  std::unordered_map<std::uint64_t, std::uint64_t> state_hash_at_;  // applied index -> hash
  std::unordered_map<std::uint64_t, std::uint64_t> tapped_hash_at_;  // tapped index -> data hash
  // Metrics.
  std::unordered_map<std::uint64_t, std::int64_t> proposed_at_us_;  // data hash -> time
  std::optional<std::int64_t> leader_crash_us_;
  std::uint64_t crashed_leader_term_ = 0;
  std::uint64_t sighting_seq_ = 0;
  std::vector<int> node_of_id_;
  int leader_burst_ = 0;                       // messages of the current step sent by the leader
  std::optional<std::int64_t> voter_crash_us_;  // pending replacement: when
  NodeId crashed_voter_ = kNoNode;              //   and whom
  std::size_t target_voters_ = 0;
};

// Builds a ClusterSim from the config, runs it for config.duration_s, returns the report.
SimReport RunSimulation(const SimConfig& config);

// FNV-1a 64 of a byte string (used for the safety bookkeeping).
std::uint64_t HashBytes(std::span<const std::uint8_t> bytes);

}  // namespace swarmbox::raft::sim
