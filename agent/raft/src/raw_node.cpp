#include "swarmbox/raft/raw_node.hpp"

#include <algorithm>
#include <functional>
#include <set>
#include <string>
#include <tuple>

namespace swarmbox::raft {

std::string_view RoleName(Role role) {
  switch (role) {
    case Role::kFollower: return "follower";
    case Role::kPreCandidate: return "pre_candidate";
    case Role::kCandidate: return "candidate";
    case Role::kLeader: return "leader";
  }
  return "unknown";
}

std::string_view MessageTypeName(MessageType type) {
  switch (type) {
    case MessageType::kHup: return "Hup";
    case MessageType::kBeat: return "Beat";
    case MessageType::kCheckQuorum: return "CheckQuorum";
    case MessageType::kProp: return "Prop";
    case MessageType::kApp: return "App";
    case MessageType::kAppResp: return "AppResp";
    case MessageType::kVote: return "Vote";
    case MessageType::kVoteResp: return "VoteResp";
    case MessageType::kPreVote: return "PreVote";
    case MessageType::kPreVoteResp: return "PreVoteResp";
    case MessageType::kSnap: return "Snap";
    case MessageType::kHeartbeat: return "Heartbeat";
    case MessageType::kHeartbeatResp: return "HeartbeatResp";
  }
  return "Unknown";
}

bool IsLocalMessage(MessageType type) {
  return type == MessageType::kHup || type == MessageType::kBeat ||
         type == MessageType::kCheckQuorum;
}

Status Config::Validate() const {
  auto bad = [](std::string msg) { return Error(ErrorCode::kInvalidArgument, std::move(msg), "raft config"); };
  if (id == kNoNode) return bad("id must be non-zero");
  if (voters.empty()) return bad("voters must not be empty");
  std::set<NodeId> seen;
  for (NodeId v : voters) {
    if (v == kNoNode) return bad("voter id 0 is reserved");
    if (!seen.insert(v).second) return bad("voter " + std::to_string(v) + " listed twice");
  }
  for (NodeId l : learners) {
    if (l == kNoNode) return bad("learner id 0 is reserved");
    if (!seen.insert(l).second) return bad("learner " + std::to_string(l) + " listed twice or also a voter");
  }
  if (!seen.count(id)) return bad("id " + std::to_string(id) + " is not among the voters or the learners");
  if (learner_heartbeat_ticks <= 0) return bad("learner_heartbeat_ticks must be > 0");
  if (heartbeat_ticks <= 0) return bad("heartbeat_ticks must be > 0");
  if (election_ticks <= heartbeat_ticks) {
    return bad("election_ticks (" + std::to_string(election_ticks) +
               ") must be greater than heartbeat_ticks (" + std::to_string(heartbeat_ticks) + ")");
  }
  if (max_entries_per_msg == 0) return bad("max_entries_per_msg must be > 0");
  return Ok{};
}

RawNode::RawNode(const Config& config) : config_(config) {
  std::sort(config_.voters.begin(), config_.voters.end());
  std::sort(config_.learners.begin(), config_.learners.end());
  conf_ = ConfState{config_.voters, config_.learners};
  known_.insert(conf_.voters.begin(), conf_.voters.end());
  known_.insert(conf_.learners.begin(), conf_.learners.end());
  rng_state_ = config.seed ^ (0x9E3779B97F4A7C15ULL * config.id);
}

namespace {

// The stored state a node may start from: entries contiguous after the snapshot, the commit
// within them, the term not below the last entry's.
Status CheckPersistentState(const PersistentState& state) {
  const std::uint64_t snap_index = state.snapshot.index;
  for (std::size_t k = 0; k < state.entries.size(); ++k) {
    if (state.entries[k].index != snap_index + 1 + k) {
      return Error(ErrorCode::kInvalidArgument,
                   "stored entries are not contiguous after snapshot " + std::to_string(snap_index) +
                       ": entry " + std::to_string(k) + " has index " +
                       std::to_string(state.entries[k].index),
                   "raft state");
    }
  }
  const std::uint64_t last = snap_index + state.entries.size();
  const HardState& hs = state.hard_state;
  if (hs.commit > last) {
    return Error(ErrorCode::kInvalidArgument,
                 "stored commit " + std::to_string(hs.commit) + " is beyond the last stored index " +
                     std::to_string(last),
                 "raft state");
  }
  const std::uint64_t last_term = state.entries.empty() ? state.snapshot.term : state.entries.back().term;
  if (hs.term < last_term) {
    return Error(ErrorCode::kInvalidArgument,
                 "stored term " + std::to_string(hs.term) + " is below the last entry's term " +
                     std::to_string(last_term),
                 "raft state");
  }
  return Ok{};
}

}  // namespace

Result<RawNode> RawNode::Create(const Config& config, PersistentState state) {
  if (auto s = config.Validate(); !s) return s.error();
  if (auto s = CheckPersistentState(state); !s) return s.error();
  const std::uint64_t snap_index = state.snapshot.index;
  const HardState hs = state.hard_state;
  RawNode node(config);
  if (!state.snapshot.conf.empty()) {
    // The membership at the snapshot; the committed changes after it re-apply with the entries.
    node.conf_ = state.snapshot.conf;
    node.known_.insert(node.conf_.voters.begin(), node.conf_.voters.end());
    node.known_.insert(node.conf_.learners.begin(), node.conf_.learners.end());
  }
  node.log_ = RaftLog(state.snapshot, std::move(state.entries), std::max(hs.commit, snap_index));
  node.snapshot_ = std::move(state.snapshot);
  // A fresh node starts in term 1 (as etcd-io/raft bootstraps), so every wire message carries a
  // non-zero term; the bump reaches storage with the first Ready.
  node.BecomeFollower(std::max<std::uint64_t>(hs.term, 1), kNoNode);
  if (hs.term != 0) node.vote_ = hs.vote;
  node.prev_hard_state_ = hs;
  node.prev_soft_state_ = {node.lead_, node.role_};
  return node;
}

std::uint64_t RawNode::NextRandom() {
  // splitmix64: small, seedable, identical on every platform.
  std::uint64_t z = (rng_state_ += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

const Progress* RawNode::progress(NodeId peer) const {
  auto it = progress_.find(peer);
  return it == progress_.end() ? nullptr : &it->second;
}

// --- roles ---------------------------------------------------------------------------------------

void RawNode::Reset(std::uint64_t term) {
  if (term_ != term) {
    term_ = term;
    vote_ = kNoNode;
  }
  lead_ = kNoNode;
  election_elapsed_ = 0;
  heartbeat_elapsed_ = 0;
  // Raft §5.2: randomised election timeouts make split votes rare.
  const auto span = static_cast<std::uint64_t>(config_.election_ticks);
  randomized_election_timeout_ = config_.election_ticks + static_cast<int>(NextRandom() % span);
  votes_.clear();
  ResetProgress();
}

void RawNode::ResetProgress() {
  progress_.clear();
  for (const auto* set : {&conf_.voters, &conf_.learners}) {
    for (NodeId v : *set) {
      Progress pr;
      pr.next = log_.last_index() + 1;
      if (v == config_.id) pr.match = log_.last_index();
      progress_[v] = pr;
    }
  }
  if (!progress_.count(config_.id)) {
    // Removed from the configuration: keep our own entry so the leader-side code stays total.
    Progress pr;
    pr.next = log_.last_index() + 1;
    pr.match = log_.last_index();
    progress_[config_.id] = pr;
  }
}

void RawNode::BecomeFollower(std::uint64_t term, NodeId lead) {
  Reset(term);
  lead_ = lead;
  role_ = Role::kFollower;
}

void RawNode::BecomePreCandidate() {
  SWARMBOX_CHECK(role_ != Role::kLeader);
  // thesis §9.6: a pre-candidate changes neither its term nor its vote.
  votes_.clear();
  lead_ = kNoNode;
  role_ = Role::kPreCandidate;
}

void RawNode::BecomeCandidate() {
  SWARMBOX_CHECK(role_ != Role::kLeader);
  // Raft §5.2: increment the term, vote for self.
  Reset(term_ + 1);
  vote_ = config_.id;
  role_ = Role::kCandidate;
}

void RawNode::BecomeLeader() {
  SWARMBOX_CHECK(role_ == Role::kCandidate);
  Reset(term_);
  lead_ = config_.id;
  role_ = Role::kLeader;
  progress_[config_.id].BecomeReplicate();
  progress_[config_.id].recent_active = true;
  // Raft §8: a new leader commits a blank no-op entry of its own term, which also commits every
  // earlier entry it holds (§5.4.2).
  Entry noop;
  noop.type = EntryType::kEmpty;
  AppendEntries({noop});
  // No membership change before the no-op of this term is applied (committed): a change proposed
  // earlier could race one of a previous leader still in the log (thesis §4.1, the 2015 fix).
  pending_conf_index_ = log_.last_index();
}

void RawNode::Campaign() {
  Message m;
  m.type = MessageType::kHup;
  (void)Step(m);
}

void RawNode::StartCampaign(bool pre_vote) {
  if (pre_vote) {
    BecomePreCandidate();  // keeps its term: asks for term + 1 without taking it (thesis §9.6)
  } else {
    BecomeCandidate();
  }
  if (Poll(config_.id, true) == VoteResult::kWon) {
    // A single-node cluster wins at once.
    if (pre_vote) {
      StartCampaign(false);
    } else {
      BecomeLeader();
    }
    return;
  }
  SendVoteRequests();
}

void RawNode::SendVoteRequests() {
  const bool pre = role_ == Role::kPreCandidate;
  for (NodeId v : conf_.voters) {
    if (v == config_.id || votes_.count(v)) continue;
    Message m;
    m.type = pre ? MessageType::kPreVote : MessageType::kVote;
    m.to = v;
    m.term = pre ? term_ + 1 : term_;  // a pre-vote asks for the term it would use
    m.index = log_.last_index();       // Raft §5.4.1: the candidate's last log index and term
    m.log_term = log_.last_term();
    Send(std::move(m));
  }
}

RawNode::VoteResult RawNode::Poll(NodeId from, bool granted) {
  votes_.emplace(from, granted);  // the first answer from a voter counts
  std::size_t yes = 0, no = 0;
  for (const auto& [id, v] : votes_) {
    if (IsVoter(conf_, id)) (v ? yes : no)++;  // only the voters of our configuration count
  }
  if (yes >= Quorum()) return VoteResult::kWon;
  if (no > conf_.voters.size() - Quorum()) return VoteResult::kLost;
  return VoteResult::kPending;
}

// --- ticks ---------------------------------------------------------------------------------------

void RawNode::Tick() {
  SWARMBOX_CHECK(!ready_outstanding_);
  if (role_ == Role::kLeader) {
    TickHeartbeat();
  } else {
    TickElection();
  }
}

void RawNode::TickElection() {
  ++election_elapsed_;
  // Raft §5.1: servers retry RPCs that get no timely response. The radio loses datagrams, so a
  // (pre-)candidate asks the voters that have not answered again every two heartbeat intervals
  // (about a round trip) instead of losing the whole election round to one lost message.
  // Vote requests are idempotent: a voter answers a repeated request the same way.
  if ((role_ == Role::kCandidate || role_ == Role::kPreCandidate) &&
      election_elapsed_ % (2 * config_.heartbeat_ticks) == 0 &&
      election_elapsed_ < randomized_election_timeout_) {
    SendVoteRequests();
  }
  if (election_elapsed_ >= randomized_election_timeout_) {
    election_elapsed_ = 0;
    Message m;
    m.type = MessageType::kHup;
    (void)Step(m);
  }
}

void RawNode::TickHeartbeat() {
  ++heartbeat_elapsed_;
  ++election_elapsed_;
  for (auto& [id, pr] : progress_) {
    if (id != config_.id) ++pr.inactive_ticks;
  }
  if (election_elapsed_ >= config_.election_ticks) {
    election_elapsed_ = 0;
    if (config_.check_quorum) {
      Message m;
      m.type = MessageType::kCheckQuorum;
      (void)Step(m);
    }
  }
  if (role_ != Role::kLeader) return;
  if (heartbeat_elapsed_ >= config_.heartbeat_ticks) {
    heartbeat_elapsed_ = 0;
    Message m;
    m.type = MessageType::kBeat;
    (void)Step(m);
  }
  TickLearners();
}

void RawNode::TickLearners() {
  if (role_ != Role::kLeader || conf_.learners.empty()) return;
  const auto period = static_cast<std::uint64_t>(config_.learner_heartbeat_ticks);
  const std::uint64_t slot = learner_slot_++ % period;
  for (std::uint64_t k = slot; k < conf_.learners.size(); k += period) {
    const NodeId to = conf_.learners[static_cast<std::size_t>(k)];
    const Progress& pr = progress_[to];
    if (pr.match < log_.last_index() && !pr.IsPaused()) {
      SendAppend(to);
    } else {
      SendHeartbeat(to);
    }
  }
}

// --- step ----------------------------------------------------------------------------------------

Status RawNode::Propose(Bytes data) {
  Message m;
  m.type = MessageType::kProp;
  m.from = config_.id;
  Entry e;
  e.data = std::move(data);
  m.entries.push_back(std::move(e));
  return Step(m);
}

Status RawNode::ProposeConfChange(const ConfChange& change) {
  SWARMBOX_CHECK(!ready_outstanding_);
  auto unavailable = [](std::string why) { return Error(ErrorCode::kUnavailable, std::move(why), "raft conf change"); };
  if (role_ != Role::kLeader) return unavailable("not the leader");
  if (pending_conf_index_ > log_.applied()) {
    return unavailable("a membership change (or this leader's no-op) at index " + std::to_string(pending_conf_index_) +
                       " is not applied yet (applied " + std::to_string(log_.applied()) + ")");
  }
  if (change.op == ConfChangeOp::kRemoveNode && change.node == config_.id) {
    return Error(ErrorCode::kInvalidArgument, "the leader cannot remove itself", "raft conf change");
  }
  if (auto next = ApplyConfChange(conf_, change); !next) return next.error();
  Entry e;
  e.type = EntryType::kConfChange;
  e.data = EncodeConfChange(change);
  AppendEntries({e});
  pending_conf_index_ = log_.last_index();
  BcastAppend();
  return Ok{};
}

// Step follows etcd-io/raft's raft.Step: check the message, settle the term (Raft §5.1), answer
// the messages every role handles (a campaign, a vote request), then step by role, one handler
// per message type.
Status RawNode::Step(const Message& m) {
  SWARMBOX_CHECK(!ready_outstanding_);
  if (auto s = CheckMessage(m); !s) return s;
  if (IsLocalMessage(m.type) || m.type == MessageType::kProp) {
    // Local messages and proposals carry no term.
  } else if (m.term > term_) {
    if (!StepHigherTerm(m)) return Ok{};
  } else if (m.term < term_) {
    StepLowerTerm(m);
    return Ok{};
  }
  switch (m.type) {
    case MessageType::kHup:
      // Only a voter campaigns (etcd's promotable()): learners and removed nodes never do.
      if (role_ != Role::kLeader && is_voter()) StartCampaign(config_.pre_vote);
      return Ok{};
    case MessageType::kVote:
    case MessageType::kPreVote:
      HandleVoteRequest(m);
      return Ok{};
    default:
      break;
  }
  switch (role_) {
    case Role::kLeader:
      if (m.type == MessageType::kProp && m.entries.empty()) {
        return Error(ErrorCode::kInvalidArgument, "empty proposal", "raft step");
      }
      StepLeader(m);
      return Ok{};
    case Role::kPreCandidate:
    case Role::kCandidate:
      return StepCandidate(m);
    case Role::kFollower:
      return StepFollower(m);
  }
  return Ok{};
}

Status RawNode::CheckMessage(const Message& m) const {
  if (IsLocalMessage(m.type) || m.type == MessageType::kProp) return Ok{};
  if (!known_.count(m.from) || m.from == config_.id) {
    return Error(ErrorCode::kInvalidArgument,
                 "message " + std::string(MessageTypeName(m.type)) + " from unknown node " +
                     std::to_string(m.from),
                 "raft step");
  }
  if (m.term == 0) {
    return Error(ErrorCode::kInvalidArgument,
                 "message " + std::string(MessageTypeName(m.type)) + " without a term", "raft step");
  }
  return Ok{};
}

bool RawNode::StepHigherTerm(const Message& m) {
  if (m.type == MessageType::kVote || m.type == MessageType::kPreVote) {
    // thesis §4.2.3 / §6.2: while we hear from a leader within the minimum election timeout,
    // ignore (pre-)votes, so a node cut off and rejoining cannot depose a healthy leader.
    const bool in_lease = config_.check_quorum && lead_ != kNoNode &&
                          election_elapsed_ < config_.election_ticks;
    if (in_lease) return false;
  }
  if (m.type == MessageType::kPreVote) {
    // thesis §9.6: never change our term in response to a PreVote.
  } else if (m.type == MessageType::kPreVoteResp && !m.reject) {
    // A granted pre-vote carries the future term we asked for: not a reason to step down.
  } else {
    // Raft §5.1: a higher term makes us a follower of that term.
    const bool from_leader = m.type == MessageType::kApp || m.type == MessageType::kHeartbeat ||
                             m.type == MessageType::kSnap;
    BecomeFollower(m.term, from_leader ? m.from : kNoNode);
  }
  return true;
}

void RawNode::StepLowerTerm(const Message& m) {
  if ((config_.check_quorum || config_.pre_vote) &&
      (m.type == MessageType::kHeartbeat || m.type == MessageType::kApp)) {
    // A stale leader (e.g. rejoining after a partition) would never learn of the new term if
    // we stayed silent, since PreVote keeps our term from reaching it through elections: answer
    // with our term so it steps down (etcd-io/raft).
    Message r;
    r.type = MessageType::kAppResp;
    r.to = m.from;
    Send(std::move(r));
  } else if (m.type == MessageType::kPreVote) {
    Message r;
    r.type = MessageType::kPreVoteResp;
    r.to = m.from;
    r.term = term_;
    r.reject = true;
    Send(std::move(r));
  }
  // Raft §5.1: otherwise a stale-term request is ignored.
}

void RawNode::HandleVoteRequest(const Message& m) {
  // Raft §5.2: one vote per term, first come first served; §5.4.1: only for a log at least as
  // up-to-date as ours. A pre-vote for a future term does not bind us.
  const bool can_vote = vote_ == m.from || (vote_ == kNoNode && lead_ == kNoNode) ||
                        (m.type == MessageType::kPreVote && m.term > term_);
  Message r;
  r.type = m.type == MessageType::kVote ? MessageType::kVoteResp : MessageType::kPreVoteResp;
  r.to = m.from;
  if (can_vote && log_.IsUpToDate(m.index, m.log_term)) {
    r.term = m.term;
    if (m.type == MessageType::kVote) {
      election_elapsed_ = 0;
      vote_ = m.from;
    }
  } else {
    r.term = term_;
    r.reject = true;
  }
  Send(std::move(r));
  // Pre-candidate yield (a SwarmBox addition, not in etcd-io/raft): on a slow radio
  // (round trip ~ 200 ms) the pre-vote round lets followers whose timers fired within ~100 ms
  // of each other all reach the real election and split the vote. A pre-candidate that hears
  // the pre-vote of a better one (more up-to-date log, ties broken by the higher id) steps
  // back and restarts its timer. Only timing changes: no term, vote or log does.
  if (m.type == MessageType::kPreVote && role_ == Role::kPreCandidate && !r.reject &&
      std::tuple(m.log_term, m.index, m.from) >
          std::tuple(log_.last_term(), log_.last_index(), config_.id)) {
    BecomeFollower(term_, kNoNode);
  }
}

void RawNode::StepLeader(const Message& m) {
  switch (m.type) {
    case MessageType::kBeat:
      BcastHeartbeat();
      return;
    case MessageType::kCheckQuorum:
      CheckQuorum();
      return;
    case MessageType::kProp: {
      std::vector<Entry> entries = m.entries;
      for (Entry& e : entries) e.type = EntryType::kNormal;
      AppendEntries(std::move(entries));
      BcastAppend();
      return;
    }
    default:
      break;
  }
  auto it = progress_.find(m.from);
  if (it == progress_.end()) return;
  if (m.type == MessageType::kAppResp) {
    HandleAppendResponse(it->second, m);
  } else if (m.type == MessageType::kHeartbeatResp) {
    HandleHeartbeatResponse(it->second, m);
  }
}

void RawNode::CheckQuorum() {
  // thesis §6.2: a leader that has not heard from a quorum in an election timeout steps down,
  // so clients (and the mission) stop waiting on a leader that cannot commit.
  std::size_t active = 0;
  for (auto& [id, pr] : progress_) {
    if (IsVoter(conf_, id) && (id == config_.id || pr.recent_active)) ++active;
    if (id != config_.id) pr.recent_active = false;
  }
  if (active < Quorum()) BecomeFollower(term_, kNoNode);
}

void RawNode::HandleAppendResponse(Progress& pr, const Message& m) {
  pr.recent_active = true;
  pr.inactive_ticks = 0;
  pr.heard = true;
  if (m.reject) {
    // Raft §5.3: after a rejection, decrement nextIndex and retry (faster with the hint).
    if (pr.MaybeDecrTo(m.index, m.reject_hint)) {
      if (pr.state == Progress::State::kReplicate) pr.BecomeProbe();
      SendAppend(m.from);
    }
    return;
  }
  const bool was_paused = pr.IsPaused();
  if (!pr.MaybeUpdate(m.index)) return;
  if (pr.state == Progress::State::kProbe) {
    pr.BecomeReplicate();
  } else if (pr.state == Progress::State::kSnapshot && pr.match >= pr.pending_snapshot) {
    pr.BecomeProbe();
    pr.BecomeReplicate();
  }
  const bool committed = MaybeCommit();
  if (committed) {
    BcastAppend();  // tell followers the new commit index
  }
  // Learner pacing: a learner less than one full message behind waits for its next slot;
  // one further behind (restarted, new) catches up at the pace of its own answers.
  if (IsLearner(conf_, m.from) &&
      log_.last_index() - progress_[m.from].match < config_.max_entries_per_msg) {
    return;
  }
  if (was_paused && !committed) SendAppend(m.from);
  // Keep the pipeline full while the follower lags behind.
  while (progress_[m.from].next <= log_.last_index() && SendAppend(m.from)) {
    if (progress_[m.from].state != Progress::State::kReplicate) break;
  }
}

void RawNode::HandleHeartbeatResponse(Progress& pr, const Message& m) {
  pr.recent_active = true;
  pr.inactive_ticks = 0;
  pr.heard = true;
  pr.probe_sent = false;
  // The follower is alive: if an InstallSnapshot was lost, try again.
  if (pr.state == Progress::State::kSnapshot && pr.match < pr.pending_snapshot) pr.BecomeProbe();
  if (pr.match < log_.last_index()) SendAppend(m.from);
}

Status RawNode::StepCandidate(const Message& m) {
  const MessageType my_resp =
      role_ == Role::kPreCandidate ? MessageType::kPreVoteResp : MessageType::kVoteResp;
  switch (m.type) {
    case MessageType::kProp:
      return Error(ErrorCode::kUnavailable, "proposal dropped: no leader (election in progress)",
                   "raft step");
    case MessageType::kApp:
      BecomeFollower(m.term, m.from);  // Raft §5.2: a leader of our term exists
      HandleAppendEntries(m);
      return Ok{};
    case MessageType::kHeartbeat:
      BecomeFollower(m.term, m.from);
      HandleHeartbeat(m);
      return Ok{};
    case MessageType::kSnap:
      BecomeFollower(m.term, m.from);
      HandleSnapshot(m);
      return Ok{};
    default:
      break;
  }
  if (m.type == my_resp) HandleVoteResponse(m);
  return Ok{};
}

void RawNode::HandleVoteResponse(const Message& m) {
  switch (Poll(m.from, !m.reject)) {
    case VoteResult::kWon:
      if (role_ == Role::kPreCandidate) {
        StartCampaign(false);
      } else {
        BecomeLeader();
        BcastAppend();
      }
      break;
    case VoteResult::kLost:
      BecomeFollower(term_, kNoNode);
      break;
    case VoteResult::kPending:
      break;
  }
}

Status RawNode::StepFollower(const Message& m) {
  switch (m.type) {
    case MessageType::kProp: {
      if (lead_ == kNoNode) {
        return Error(ErrorCode::kUnavailable, "proposal dropped: no known leader", "raft step");
      }
      Message fwd = m;
      fwd.to = lead_;
      fwd.term = 0;
      Send(std::move(fwd));
      return Ok{};
    }
    case MessageType::kApp: return FromLeader(m, &RawNode::HandleAppendEntries);
    case MessageType::kHeartbeat: return FromLeader(m, &RawNode::HandleHeartbeat);
    case MessageType::kSnap: return FromLeader(m, &RawNode::HandleSnapshot);
    default:
      return Ok{};
  }
}

Status RawNode::FromLeader(const Message& m, void (RawNode::*handle)(const Message&)) {
  election_elapsed_ = 0;
  lead_ = m.from;
  (this->*handle)(m);
  return Ok{};
}

// --- replication ---------------------------------------------------------------------------------

void RawNode::AppendEntries(std::vector<Entry> entries) {
  std::uint64_t index = log_.last_index();
  for (Entry& e : entries) {
    e.term = term_;
    e.index = ++index;
  }
  log_.Append(entries);
  progress_[config_.id].MaybeUpdate(log_.last_index());
  MaybeCommit();
}

bool RawNode::MaybeCommit() {
  // Raft §5.3/§5.4.2: the highest index replicated on a majority, if it is of the current term.
  // Only the voters' logs count (learners never form a quorum).
  std::vector<std::uint64_t> matches;
  for (NodeId v : conf_.voters) matches.push_back(progress_[v].match);
  std::sort(matches.begin(), matches.end(), std::greater<>());
  return log_.MaybeCommit(matches[Quorum() - 1], term_);
}

bool RawNode::SendAppend(NodeId to) {
  Progress& pr = progress_[to];
  if (pr.IsPaused()) return false;
  Message m;
  m.to = to;
  const auto prev_term = log_.Term(pr.next - 1);
  if (!prev_term) {
    // Raft §7: the entries the follower needs are compacted: send the snapshot instead.
    SWARMBOX_CHECK(!snapshot_.empty());
    m.type = MessageType::kSnap;
    m.snapshot = snapshot_;
    pr.BecomeSnapshot(snapshot_.index);
    Send(std::move(m));
    return true;
  }
  m.type = MessageType::kApp;
  m.index = pr.next - 1;
  m.log_term = *prev_term;
  m.entries = log_.Slice(pr.next, log_.last_index() + 1, config_.max_entries_per_msg);
  m.commit = log_.committed();
  if (pr.state == Progress::State::kReplicate) {
    if (!m.entries.empty()) pr.next = m.entries.back().index + 1;
  } else if (pr.state == Progress::State::kProbe) {
    pr.probe_sent = true;
  }
  Send(std::move(m));
  return true;
}

void RawNode::BcastAppend() {
  for (NodeId v : conf_.voters) {
    if (v != config_.id) SendAppend(v);
  }
}

void RawNode::SendHeartbeat(NodeId to) {
  // The follower may not hold the leader's whole log yet: never make it commit past its match.
  Message m;
  m.type = MessageType::kHeartbeat;
  m.to = to;
  m.commit = std::min(progress_[to].match, log_.committed());
  Send(std::move(m));
}

void RawNode::BcastHeartbeat() {
  for (NodeId v : conf_.voters) {
    if (v != config_.id) SendHeartbeat(v);
  }
}

void RawNode::HandleAppendEntries(const Message& m) {
  Message r;
  r.type = MessageType::kAppResp;
  r.to = m.from;
  if (m.index < log_.committed()) {
    r.index = log_.committed();
    Send(std::move(r));
    return;
  }
  if (auto last_new = log_.MaybeAppend(m.index, m.log_term, m.commit, m.entries)) {
    r.index = *last_new;
  } else {
    // Raft §5.3: the log does not contain an entry at prevLogIndex with prevLogTerm.
    r.index = m.index;
    r.reject = true;
    r.reject_hint = log_.last_index();
  }
  Send(std::move(r));
}

void RawNode::HandleHeartbeat(const Message& m) {
  log_.CommitTo(std::min(m.commit, log_.last_index()));
  Message r;
  r.type = MessageType::kHeartbeatResp;
  r.to = m.from;
  Send(std::move(r));
}

void RawNode::HandleSnapshot(const Message& m) {
  Message r;
  r.type = MessageType::kAppResp;
  r.to = m.from;
  r.index = Restore(m.snapshot) ? log_.last_index() : log_.committed();
  Send(std::move(r));
}

bool RawNode::Restore(const Snapshot& s) {
  if (s.empty() || s.index <= log_.committed()) return false;
  if (log_.MatchTerm(s.index, s.term)) {
    // Raft §7 receiver rule 6: we already hold the snapshot's last entry: keep the log after it.
    log_.CommitTo(s.index);
    return false;
  }
  // Rule 7: discard the entire log and take the snapshot (and the membership at its index).
  log_.Restore(s);
  snapshot_ = s;
  if (!s.conf.empty()) {
    conf_ = s.conf;
    known_.insert(conf_.voters.begin(), conf_.voters.end());
    known_.insert(conf_.learners.begin(), conf_.learners.end());
  }
  snapshot_pending_ = true;
  return true;
}

void RawNode::Send(Message m) {
  m.from = config_.id;
  if (m.type == MessageType::kVote || m.type == MessageType::kPreVote ||
      m.type == MessageType::kVoteResp || m.type == MessageType::kPreVoteResp) {
    SWARMBOX_CHECK(m.term != 0);
  } else if (m.type != MessageType::kProp) {
    m.term = term_;
  }
  msgs_.push_back(std::move(m));
}

// --- ready ---------------------------------------------------------------------------------------

bool RawNode::HasReady() const {
  if (SoftState{lead_, role_} != prev_soft_state_) return true;
  if (hard_state() != prev_hard_state_) return true;
  if (snapshot_pending_ || !msgs_.empty()) return true;
  if (log_.stable_index() < log_.last_index()) return true;
  return log_.applied() < log_.committed();
}

Ready RawNode::GetReady() {
  SWARMBOX_CHECK(!ready_outstanding_);
  Ready rd;
  const SoftState ss{lead_, role_};
  if (ss != prev_soft_state_) rd.soft_state = ss;
  const HardState hs = hard_state();
  if (hs != prev_hard_state_) rd.hard_state = hs;
  if (snapshot_pending_) rd.snapshot = snapshot_;
  rd.entries = log_.Slice(log_.stable_index() + 1, log_.last_index() + 1, SIZE_MAX);
  rd.committed_entries = log_.Slice(log_.applied() + 1, log_.committed() + 1, SIZE_MAX);
  rd.messages = std::move(msgs_);
  msgs_.clear();
  ready_outstanding_ = true;
  return rd;
}

void RawNode::Advance(const Ready& rd) {
  SWARMBOX_CHECK(ready_outstanding_);
  ready_outstanding_ = false;
  if (rd.soft_state) prev_soft_state_ = *rd.soft_state;
  if (rd.hard_state) prev_hard_state_ = *rd.hard_state;
  if (!rd.snapshot.empty()) snapshot_pending_ = false;
  if (!rd.entries.empty()) log_.StableTo(rd.entries.back().index);
  if (!rd.committed_entries.empty()) {
    for (const Entry& e : rd.committed_entries) {
      if (e.type == EntryType::kConfChange) ApplyConfEntry(e);
    }
    log_.AppliedTo(rd.committed_entries.back().index);
  }
}

void RawNode::ApplyConfEntry(const Entry& e) {
  auto change = DecodeConfChange(e.data);
  Result<ConfState> next = change ? ApplyConfChange(conf_, *change) : Result<ConfState>(change.error());
  if (!next) {
    ++invalid_conf_changes_;  // the same on every node: the committed log and start are the same
    return;
  }
  conf_ = std::move(*next);
  known_.insert(change->node);
  if (change->op == ConfChangeOp::kAddLearner) {
    Progress pr;
    pr.next = log_.last_index() + 1;
    progress_.emplace(change->node, pr);
  } else if (change->op == ConfChangeOp::kRemoveNode && change->node != config_.id) {
    progress_.erase(change->node);
    votes_.erase(change->node);
  }
  if (role_ != Role::kLeader) return;
  if (!is_voter()) {
    BecomeFollower(term_, kNoNode);  // removed: a non-voter cannot lead
    return;
  }
  // A smaller quorum may commit more now (etcd: maybeCommit after a change).
  if (MaybeCommit()) BcastAppend();
}

Status RawNode::Compact(std::uint64_t index, Bytes data) {
  SWARMBOX_CHECK(!ready_outstanding_);
  if (index <= log_.snapshot_index()) {
    return Error(ErrorCode::kInvalidArgument,
                 "compact to " + std::to_string(index) + ": already compacted to " +
                     std::to_string(log_.snapshot_index()),
                 "raft compact");
  }
  if (index > log_.applied()) {
    return Error(ErrorCode::kInvalidArgument,
                 "compact to " + std::to_string(index) + ": beyond applied index " +
                     std::to_string(log_.applied()),
                 "raft compact");
  }
  snapshot_ = Snapshot{index, *log_.Term(index), std::move(data), conf_};
  log_.Compact(index);
  return Ok{};
}

}  // namespace swarmbox::raft
