#include "swarmbox/raft/node_driver.hpp"

#include <algorithm>
#include <set>

#include "swarmbox/raft/message_codec.hpp"

namespace swarmbox::raft {
namespace {

// Open's restart from the snapshot in storage: `machine` holds the state as of its index.
Status RestoreStoredSnapshot(const Snapshot& snapshot, StateMachine& machine) {
  if (auto s = machine.Restore(snapshot.data); !s) {
    return s.error().Context("restoring the state machine from the stored snapshot " +
                             std::to_string(snapshot.index));
  }
  const auto* m = dynamic_cast<const MissionStateMachine*>(&machine);
  if (m != nullptr && m->mission().applied_index() != snapshot.index) {
    return Error(ErrorCode::kProtocol,
                 "stored snapshot " + std::to_string(snapshot.index) + " holds a mission applied to " +
                     std::to_string(m->mission().applied_index()),
                 "raft storage");
  }
  return Ok{};
}

}  // namespace

Result<Config> DriverConfig::ToRaftConfig() const {
  auto bad = [](std::string msg) {
    return Error(ErrorCode::kInvalidArgument, std::move(msg), "raft driver config");
  };
  if (self.empty()) return bad("self name is empty");
  std::vector<std::string> names = members;
  std::sort(names.begin(), names.end());
  if (std::adjacent_find(names.begin(), names.end()) != names.end()) {
    return bad("member names must be distinct");
  }
  auto it = std::find(names.begin(), names.end(), self);
  if (it == names.end()) return bad("self '" + self + "' is not among the members");
  if (auto s = ValidateTiming(); !s) return s.error();
  Config c;
  c.id = static_cast<NodeId>(it - names.begin()) + 1;
  std::vector<std::string> voting = voters;
  std::sort(voting.begin(), voting.end());
  if (std::adjacent_find(voting.begin(), voting.end()) != voting.end()) {
    return bad("voter names must be distinct");
  }
  for (const std::string& v : voting) {
    if (!std::binary_search(names.begin(), names.end(), v)) {
      return bad("voter '" + v + "' is not among the members");
    }
  }
  for (std::size_t k = 0; k < names.size(); ++k) {
    const bool votes = voting.empty() || std::binary_search(voting.begin(), voting.end(), names[k]);
    (votes ? c.voters : c.learners).push_back(k + 1);
  }
  c.learner_heartbeat_ticks = learner_heartbeat_ms / tick_ms;
  c.heartbeat_ticks = heartbeat_ms / tick_ms;
  c.election_ticks = election_timeout_ms / tick_ms;
  c.pre_vote = pre_vote;
  c.check_quorum = check_quorum;
  c.seed = seed;
  c.max_entries_per_msg = max_entries_per_msg;
  if (auto s = c.Validate(); !s) return s.error();
  return c;
}

Status DriverConfig::ValidateTiming() const {
  auto bad = [](std::string msg) {
    return Error(ErrorCode::kInvalidArgument, std::move(msg), "raft driver config");
  };
  if (tick_ms <= 0) return bad("tick_ms must be > 0");
  if (heartbeat_ms <= 0 || heartbeat_ms % tick_ms != 0 || election_timeout_ms % tick_ms != 0) {
    return bad("heartbeat_ms (" + std::to_string(heartbeat_ms) + ") and election_timeout_ms (" +
               std::to_string(election_timeout_ms) + ") must be multiples of tick_ms (" +
               std::to_string(tick_ms) + ")");
  }
  if (election_timeout_ms <= heartbeat_ms) {
    return bad("election_timeout_ms (" + std::to_string(election_timeout_ms) +
               ") must be greater than heartbeat_ms (" + std::to_string(heartbeat_ms) + ")");
  }
  if (learner_heartbeat_ms <= 0 || learner_heartbeat_ms % tick_ms != 0) {
    return bad("learner_heartbeat_ms (" + std::to_string(learner_heartbeat_ms) +
               ") must be a positive multiple of tick_ms (" + std::to_string(tick_ms) + ")");
  }
  if (voter_lost_ms < 0) return bad("voter_lost_ms must be >= 0 (0: 3 x election_timeout_ms)");
  if (snapshot_every_entries == 0) return bad("snapshot_every_entries must be > 0");
  if (max_entries_per_msg == 0) return bad("max_entries_per_msg must be > 0");
  return Ok{};
}

NodeDriver::NodeDriver(DriverConfig config, std::vector<std::string> names, std::uint32_t tag,
                       RawNode node, std::unique_ptr<StateMachine> machine, std::uint64_t applied,
                       std::vector<Committed> tap, Storage& storage, Transport& transport,
                       const Clock& clock, EventSink sink)
    : config_(std::move(config)),
      names_(std::move(names)),
      cluster_tag_(tag),
      node_(std::move(node)),
      machine_(std::move(machine)),
      mission_machine_(dynamic_cast<const MissionStateMachine*>(machine_.get())),
      applied_(applied),
      tap_(std::move(tap)),
      storage_(storage),
      transport_(transport),
      clock_(clock),
      sink_(std::move(sink)) {}

Result<std::unique_ptr<NodeDriver>> NodeDriver::Open(const DriverConfig& config, Storage& storage,
                                                     Transport& transport, const Clock& clock,
                                                     EventSink sink) {
  return Open(config, storage, transport, clock, std::move(sink), nullptr);
}

Result<std::unique_ptr<NodeDriver>> NodeDriver::Open(const DriverConfig& config, Storage& storage,
                                                     Transport& transport, const Clock& clock,
                                                     EventSink sink,
                                                     std::unique_ptr<StateMachine> machine) {
  auto rc = config.ToRaftConfig();
  if (!rc) return rc.error();
  if (!machine) machine = std::make_unique<MissionStateMachine>();
  auto state = storage.Load();
  if (!state) return state.error().Context("loading raft state");
  std::uint64_t applied = 0;
  std::vector<Committed> tap;
  if (!state->snapshot.empty()) {
    if (auto s = RestoreStoredSnapshot(state->snapshot, *machine); !s) return s.error();
    applied = state->snapshot.index;
    if (config.tap_committed) machine->ReplayRestored(0, &tap);
  }
  auto node = RawNode::Create(*rc, std::move(*state));
  if (!node) return node.error().Context("restarting raft");
  std::vector<std::string> names = config.members;
  std::sort(names.begin(), names.end());
  const std::uint32_t tag = ClusterTag(names);
  std::unique_ptr<NodeDriver> d(new NodeDriver(config, std::move(names), tag, std::move(*node),
                                               std::move(machine), applied, std::move(tap),
                                               storage, transport, clock, std::move(sink)));
  d->conf_applied_ = d->node_.conf_state();  // as of the snapshot: later changes re-apply below
  if (!rc->learners.empty()) d->target_voters_ = rc->voters.size();
  // Hand over what the restart produced (the term bump of a fresh node, re-applying the
  // committed entries after the snapshot).
  if (auto s = d->Process(); !s) return s.error();
  return d;
}

NodeId NodeDriver::IdOf(const std::string& name) const {
  auto it = std::lower_bound(names_.begin(), names_.end(), name);
  if (it == names_.end() || *it != name) return kNoNode;
  return static_cast<NodeId>(it - names_.begin()) + 1;
}

const MissionState& NodeDriver::mission() const {
  SWARMBOX_CHECK(mission_machine_ != nullptr);  // mission() of a driver without a mission
  return mission_machine_->mission();
}

void NodeDriver::TakeCommitted(std::vector<Committed>* out) {
  out->clear();
  out->swap(tap_);
}

std::string NodeDriver::leader() const {
  return node_.lead() == kNoNode ? std::string() : NameOf(node_.lead());
}

void NodeDriver::Emit(const LogEvent& e) const {
  if (sink_) sink_(e);
}

Status NodeDriver::Stop(Error e) {
  stop_error_ = e;
  Emit(LogEvent(clock_.NowS(), config_.self, "raft_stopped").Add("reason", e.ToString()));
  return e;
}

Status NodeDriver::Tick() {
  if (stop_error_) return *stop_error_;
  node_.Tick();
  SWARMBOX_TRY(Process());
  return ReplaceLostVoters();
}

Status NodeDriver::ProposeConfChange(ConfChangeOp op, const std::string& node) {
  if (stop_error_) return *stop_error_;
  const NodeId id = IdOf(node);
  if (id == kNoNode) {
    return Error(ErrorCode::kInvalidArgument, "'" + node + "' is not a member of the trial", "raft driver");
  }
  Status s = node_.ProposeConfChange(ConfChange{op, id});
  SWARMBOX_TRY(Process());
  return s;
}

Status NodeDriver::ReplaceLostVoters() {
  if (target_voters_ == 0 || !is_leader()) return Ok{};
  if (node_.pending_conf_index() > node_.log().applied()) return Ok{};  // one change at a time
  const ConfState& conf = node_.conf_state();
  const int lost_ms = config_.voter_lost_ms > 0 ? config_.voter_lost_ms : 3 * config_.election_timeout_ms;
  const int lost_ticks = (lost_ms + config_.tick_ms - 1) / config_.tick_ms;
  const int fresh_ticks = 2 * config_.learner_heartbeat_ms / config_.tick_ms;
  std::optional<ConfChange> change;
  for (NodeId v : conf.voters) {
    const Progress* pr = node_.progress(v);
    if (v != node_.id() && pr != nullptr && pr->inactive_ticks >= lost_ticks) {
      change = ConfChange{ConfChangeOp::kRemoveNode, v};
      break;
    }
  }
  if (!change && conf.voters.size() < target_voters_) {
    const Progress* best = nullptr;
    for (NodeId l : conf.learners) {
      const Progress* pr = node_.progress(l);
      if (pr == nullptr || !pr->heard || pr->inactive_ticks > fresh_ticks) continue;
      if (best == nullptr || pr->match > best->match) {
        best = pr;
        change = ConfChange{ConfChangeOp::kPromoteLearner, l};
      }
    }
  }
  if (!change) {
    for (NodeId id = 1; id <= names_.size(); ++id) {
      if (!IsVoter(conf, id) && !IsLearner(conf, id)) {
        change = ConfChange{ConfChangeOp::kAddLearner, id};
        break;
      }
    }
  }
  if (!change) return Ok{};
  (void)node_.ProposeConfChange(*change);  // refused only when leadership is lost: retried next tick
  return Process();
}

Status NodeDriver::Campaign() {
  if (stop_error_) return *stop_error_;
  node_.Campaign();
  return Process();
}

Status NodeDriver::Receive(std::span<const std::uint8_t> bytes) {
  if (stop_error_) return *stop_error_;
  auto m = DecodeMessage(bytes, cluster_tag_);
  if (!m) return m.error();
  if (m->to != node_.id()) {
    return Error(ErrorCode::kProtocol,
                 "message for node " + std::to_string(m->to) + " delivered to " + config_.self,
                 "raft driver");
  }
  if (m->from == kNoNode || m->from > names_.size()) {
    return Error(ErrorCode::kProtocol, "message from unknown node " + std::to_string(m->from),
                 "raft driver");
  }
  Status step = node_.Step(*m);
  Status processed = Process();
  if (!processed) return processed;
  return step;
}

Status NodeDriver::Propose(Bytes data) {
  if (stop_error_) return *stop_error_;
  if (data.empty()) {
    return Error(ErrorCode::kInvalidArgument,
                 "an empty entry cannot be proposed (empty entries are the leader's no-ops)",
                 "raft driver");
  }
  Status s = node_.Propose(std::move(data));
  Status processed = Process();
  if (!processed) return processed;
  return s;
}

Status NodeDriver::Propose(const MissionCommand& command) { return Propose(EncodeCommand(command)); }

std::string NodeDriver::NameOrId(NodeId id) const {
  return id >= 1 && id <= names_.size() ? NameOf(id) : "node" + std::to_string(id);
}

void NodeDriver::ApplyConfEntry(const Entry& e) {
  auto change = DecodeConfChange(e.data);
  if (!change) return;  // RawNode skips it the same way (invalid_conf_changes)
  auto next = ApplyConfChange(conf_applied_, *change);
  if (!next) return;
  conf_applied_ = std::move(*next);
  std::string voters;
  for (NodeId v : conf_applied_.voters) voters += (voters.empty() ? "" : ",") + NameOrId(v);
  Emit(LogEvent(clock_.NowS(), config_.self, "raft_conf_change")
           .Add("op", ConfChangeOpName(change->op))
           .Add("node", NameOrId(change->node))
           .Add("voters", voters)
           .Add("learners", static_cast<std::uint64_t>(conf_applied_.learners.size())));
}

void NodeDriver::ApplyEntry(const Entry& e) {
  if (e.index <= applied_) return;  // already in the restored snapshot
  applied_ = e.index;
  if (e.type == EntryType::kConfChange) {
    ApplyConfEntry(e);
    // The machine sees a membership change as a no-op: its applied index stays the log's.
    machine_->Apply(e.index, std::span<const std::uint8_t>(), EventOut(clock_.NowS(), config_.self, sink_));
    return;
  }
  // A kNormal entry is never empty (Propose refuses that); treat one like the no-op it carries.
  const bool noop = e.type == EntryType::kEmpty || e.data.empty();
  const std::span<const std::uint8_t> data = noop ? std::span<const std::uint8_t>() : e.data;
  machine_->Apply(e.index, data, EventOut(clock_.NowS(), config_.self, sink_));
  if (!noop && config_.tap_committed) tap_.push_back(Committed{e.index, e.data});
}

Status NodeDriver::Process() {
  while (node_.HasReady()) {
    Ready rd = node_.GetReady();
    // Raft §5 (Figure 2): persistent state is durable before any message that depends on it.
    if (rd.hard_state || !rd.entries.empty() || !rd.snapshot.empty()) {
      if (auto s = storage_.Save(rd.hard_state, rd.entries, rd.snapshot); !s) {
        return Stop(s.error().Context("raft storage failed, node stopped"));
      }
    }
    for (const Message& m : rd.messages) {
      const Bytes bytes = EncodeMessage(m, cluster_tag_);
      transport_.Send(NameOf(m.to), bytes);
    }
    AnnounceLeader(rd.soft_state);
    if (!rd.snapshot.empty()) {
      if (auto s = InstallSnapshot(rd.snapshot); !s) return s;
    }
    for (const Entry& e : rd.committed_entries) ApplyEntry(e);
    node_.Advance(rd);
    // The events' view of the membership and Raft's are the same function of the same log.
    SWARMBOX_CHECK(conf_applied_ == node_.conf_state());
  }
  return CompactIfDue();
}

void NodeDriver::AnnounceLeader(const std::optional<SoftState>& soft_state) {
  if (!soft_state || soft_state->lead == kNoNode ||
      (soft_state->lead == announced_lead_ && node_.term() == announced_term_)) {
    return;
  }
  announced_lead_ = soft_state->lead;
  announced_term_ = node_.term();
  Emit(LogEvent(clock_.NowS(), config_.self, "leader_elected")
           .Add("term", node_.term())
           .Add("leader", NameOf(announced_lead_)));
}

Status NodeDriver::InstallSnapshot(const Snapshot& snapshot) {
  // The snapshot is the state after its index; nothing before it is applied again.
  if (snapshot.index < applied_) {
    return Stop(Error(ErrorCode::kProtocol,
                      "snapshot at " + std::to_string(snapshot.index) +
                          " is behind the applied index " + std::to_string(applied_),
                      "raft driver"));
  }
  if (auto s = machine_->Restore(snapshot.data); !s) {
    return Stop(s.error().Context("leader sent an unreadable snapshot"));
  }
  const std::uint64_t before = applied_;
  applied_ = snapshot.index;
  if (!snapshot.conf.empty()) conf_applied_ = snapshot.conf;
  if (mission_machine_ != nullptr && mission_machine_->mission().applied_index() != applied_) {
    return Stop(Error(ErrorCode::kProtocol, "snapshot index mismatch", "raft driver"));
  }
  machine_->OnSnapshotInstalled(snapshot.index, EventOut(clock_.NowS(), config_.self, sink_));
  if (config_.tap_committed) machine_->ReplayRestored(before, &tap_);
  return Ok{};
}

// Raft §7: compact the log into a snapshot of the state machine once enough has been applied.
Status NodeDriver::CompactIfDue() {
  const std::uint64_t applied = node_.log().applied();
  if (applied >= node_.log().snapshot_index() + config_.snapshot_every_entries) {
    Snapshot snap{applied, *node_.log().Term(applied), machine_->Snapshot(), node_.conf_state()};
    if (auto s = storage_.Compact(snap); !s) {
      return Stop(s.error().Context("raft storage failed while compacting, node stopped"));
    }
    if (auto s = node_.Compact(applied, std::move(snap.data)); !s) return Stop(s.error());
  }
  return Ok{};
}

}  // namespace swarmbox::raft
