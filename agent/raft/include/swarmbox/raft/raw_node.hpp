// RawNode: the deterministic Raft state machine of one node (etcd-io/raft's RawNode + raft).
//
// The caller owns transport, durable storage, time and the random seed. It drives the node with
//   Tick()            one logical clock tick (heartbeat and election timeouts are counted in ticks),
//   Step(message)     a message received from a peer (or kProp via Propose()),
// and after every call hands the output over with the Ready/Advance protocol:
//
//   while (node.HasReady()) {
//     raft::Ready rd = node.GetReady();
//     storage.Save(rd.hard_state, rd.entries, rd.snapshot);   // durable (fsync) FIRST (Raft §5,
//     for (auto& m : rd.messages) transport.Send(m);           //   Figure 2), then send,
//     if (!rd.snapshot.empty()) state_machine.Restore(rd.snapshot.data);
//     for (auto& e : rd.committed_entries) state_machine.Apply(e);   // apply in log order (§5.3)
//     node.Advance(rd);
//   }
//
// No other call may happen between GetReady() and Advance() (checked). The node never blocks,
// allocates no threads and reads no clock: the same inputs and seed give the same outputs, which is
// what lets the cluster simulator (sim/cluster_sim.hpp) replay a failing seed.
//
// Implemented: leader election with randomised timeouts (Raft §5.2), log replication and the
// commit rule (§5.3, §5.4.2), the election restriction (§5.4.1), the leader's no-op entry (§8),
// PreVote (thesis §9.6), CheckQuorum and leader lease for votes (thesis §6.2, §4.2.3), proposal
// forwarding to the leader, log compaction and InstallSnapshot (§7), learners and one-at-a-time
// membership changes (etcd-io/raft's ConfChange, conf_change.hpp). Not implemented: joint
// consensus, leadership transfer, ReadIndex.
//
// Learners (etcd-io/raft's, for a swarm of 100 with a voting set of 5): a learner receives and
// applies the log but never campaigns, is never asked for a vote and does not count for a commit
// quorum or CheckQuorum. It answers appends and heartbeats like a follower, so the leader tracks
// its progress (match/next) as for a voter. Learner pacing (not in etcd, which relies on TCP
// flow control; our radio has a 50-frame queue): the leader does not broadcast appends or
// heartbeats to learners. Each tick it serves the learners whose slot it is, slot k of
// learner_heartbeat_ticks for the k-th learner (sorted by id) modulo that period: an append when
// the learner is behind, else a heartbeat carrying the commit index. So 95 learners cost ~95/period
// frames per tick, never 95 at once; the replies (and only they) drive any catch-up appends.
// Membership changes take effect when their entry is applied (Advance), as in etcd; the
// configuration is part of the snapshot. A leader that applies its own removal steps down.
//
// Two liveness-only additions for a lossy, slow radio (neither changes a term, vote or log entry,
// so safety is untouched; the simulator checks it): (pre-)candidates re-send unanswered vote
// requests every 2 heartbeat intervals (Raft §5.1 "servers retry RPCs"; etcd relies on TCP), and
// a pre-candidate that hears the pre-vote of a better one (more up-to-date log, then higher id)
// steps back instead of splitting the vote (not in etcd-io/raft).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/conf_change.hpp"
#include "swarmbox/raft/progress.hpp"
#include "swarmbox/raft/raft_log.hpp"
#include "swarmbox/raft/types.hpp"

namespace swarmbox::raft {

enum class Role : std::uint8_t { kFollower, kPreCandidate, kCandidate, kLeader };
std::string_view RoleName(Role role);

struct Config {
  NodeId id = kNoNode;
  // The starting membership (a snapshot's ConfState replaces it): voters and learners, ids
  // non-zero and distinct, id among one of them, at least one voter.
  std::vector<NodeId> voters;
  std::vector<NodeId> learners;
  // A follower starts an election after a random timeout in [election_ticks, 2*election_ticks)
  // without hearing from a leader (Raft §5.2); the leader sends heartbeats every heartbeat_ticks.
  int election_ticks = 10;
  int heartbeat_ticks = 2;
  bool pre_vote = true;      // thesis §9.6
  bool check_quorum = true;  // thesis §6.2
  std::size_t max_entries_per_msg = 64;
  // The leader serves each learner once per this many ticks (see the banner: learner pacing).
  int learner_heartbeat_ticks = 20;
  std::uint64_t seed = 1;    // seeds the election-timeout randomisation

  // kInvalidArgument with the reason when the configuration cannot work.
  Status Validate() const;
};

// Durable state a node restarts from (what Storage::Load returns).
struct PersistentState {
  HardState hard_state;
  Snapshot snapshot;           // latest snapshot (empty: none)
  std::vector<Entry> entries;  // contiguous, from snapshot.index + 1
};

struct SoftState {
  NodeId lead = kNoNode;
  Role role = Role::kFollower;
  bool operator==(const SoftState&) const = default;
};

struct Ready {
  std::optional<SoftState> soft_state;   // set when the leader or role changed
  std::optional<HardState> hard_state;   // set when it changed: persist
  Snapshot snapshot;                     // non-empty: persist, then restore the state machine
  std::vector<Entry> entries;            // persist; overwrite any stored entry >= entries[0].index
  std::vector<Entry> committed_entries;  // apply in order, after persisting
  std::vector<Message> messages;         // send only after the above is durable
};

class RawNode {
 public:
  // Errors (kInvalidArgument) for a bad config or inconsistent durable state.
  static Result<RawNode> Create(const Config& config, PersistentState state = {});

  void Tick();
  // A message from the network. kProp and local types are accepted too. Errors: kUnavailable when
  // a proposal is dropped (no known leader), kInvalidArgument for a malformed message.
  Status Step(const Message& m);
  // Proposes an application command (forwarded to the leader when we are a follower).
  Status Propose(Bytes data);
  // Starts an election now (as an election timeout would). A learner does not campaign.
  void Campaign();
  // Leader only: appends a membership change (conf_change.hpp). kUnavailable when not leader, when
  // a change is still in flight (appended, not applied) or before the leader applied an entry of
  // its own term; kInvalidArgument when it does not apply to the current configuration or removes
  // the leader itself.
  Status ProposeConfChange(const ConfChange& change);

  bool HasReady() const;
  Ready GetReady();
  void Advance(const Ready& rd);

  // Replaces entries up to `index` (<= applied) by a snapshot whose state machine encoding is data.
  // The caller persists the snapshot before calling this (Storage::Compact).
  Status Compact(std::uint64_t index, Bytes data);

  // Introspection (tests, the simulator's safety checks, the driver's events).
  NodeId id() const { return config_.id; }
  std::uint64_t term() const { return term_; }
  NodeId vote() const { return vote_; }
  NodeId lead() const { return lead_; }
  Role role() const { return role_; }
  const RaftLog& log() const { return log_; }
  const Snapshot& snapshot() const { return snapshot_; }
  const Config& config() const { return config_; }
  const Progress* progress(NodeId peer) const;
  // The configuration in effect (changes applied up to log().applied()).
  const ConfState& conf_state() const { return conf_; }
  bool is_voter() const { return IsVoter(conf_, config_.id); }
  bool is_learner() const { return IsLearner(conf_, config_.id); }
  // Leader: the index of the last change it appended, or of its own no-op until it appends one;
  // no new change is accepted while this is above the applied index (ProposeConfChange).
  std::uint64_t pending_conf_index() const { return pending_conf_index_; }
  // Committed conf-change entries that did not apply (invalid for the configuration they met):
  // skipped identically on every node; the simulator requires 0.
  std::uint64_t invalid_conf_changes() const { return invalid_conf_changes_; }
  HardState hard_state() const { return {term_, vote_, log_.committed()}; }
  int randomized_election_timeout() const { return randomized_election_timeout_; }

 private:
  enum class VoteResult { kPending, kWon, kLost };

  explicit RawNode(const Config& config);

  void TickElection();
  void TickHeartbeat();
  // Step's parts, in etcd-io/raft's shape: the checks and the term, then one step per role and
  // one handler per message type.
  Status CheckMessage(const Message& m) const;  // a known sender and a term (remote messages)
  bool StepHigherTerm(const Message& m);        // false: the message is dropped (leader lease)
  void StepLowerTerm(const Message& m);         // answers a stale leader or pre-candidate
  void HandleVoteRequest(const Message& m);     // kVote / kPreVote, in every role
  void StepLeader(const Message& m);
  void CheckQuorum();
  void HandleAppendResponse(Progress& pr, const Message& m);
  void HandleHeartbeatResponse(Progress& pr, const Message& m);
  Status StepCandidate(const Message& m);
  void HandleVoteResponse(const Message& m);
  Status StepFollower(const Message& m);
  // A follower hears its leader: the election timer restarts, lead_ is the sender, `handle` runs.
  Status FromLeader(const Message& m, void (RawNode::*handle)(const Message&));

  void Reset(std::uint64_t term);
  void BecomeFollower(std::uint64_t term, NodeId lead);
  void BecomePreCandidate();
  void BecomeCandidate();
  void BecomeLeader();
  void StartCampaign(bool pre_vote);
  void SendVoteRequests();  // to every voter that has not answered yet
  VoteResult Poll(NodeId from, bool granted);
  std::size_t Quorum() const { return conf_.voters.size() / 2 + 1; }
  void ResetProgress();  // one Progress per member of conf_
  void ApplyConfEntry(const Entry& e);
  void TickLearners();   // leader: the learners whose slot this tick is

  void AppendEntries(std::vector<Entry> entries);  // leader: stamp term/index, append, commit
  bool MaybeCommit();
  bool SendAppend(NodeId to);
  void BcastAppend();
  void SendHeartbeat(NodeId to);
  void BcastHeartbeat();
  void HandleAppendEntries(const Message& m);
  void HandleHeartbeat(const Message& m);
  void HandleSnapshot(const Message& m);
  bool Restore(const Snapshot& s);
  void Send(Message m);
  std::uint64_t NextRandom();

  Config config_;
  std::uint64_t term_ = 0;
  NodeId vote_ = kNoNode;
  NodeId lead_ = kNoNode;
  Role role_ = Role::kFollower;
  RaftLog log_;
  Snapshot snapshot_;  // latest snapshot, sent to followers that need compacted entries
  std::map<NodeId, Progress> progress_;  // every member (voters, learners, self)
  ConfState conf_;
  std::set<NodeId> known_;  // every id ever in a configuration: messages from others are refused
  std::uint64_t pending_conf_index_ = 0;
  std::uint64_t invalid_conf_changes_ = 0;
  std::uint64_t learner_slot_ = 0;
  std::map<NodeId, bool> votes_;
  int election_elapsed_ = 0;
  int heartbeat_elapsed_ = 0;
  int randomized_election_timeout_ = 0;
  std::uint64_t rng_state_ = 0;
  std::vector<Message> msgs_;

  // Ready bookkeeping.
  HardState prev_hard_state_;
  SoftState prev_soft_state_;
  bool snapshot_pending_ = false;  // a snapshot received from the leader awaits the caller
  bool ready_outstanding_ = false;
};

}  // namespace swarmbox::raft
