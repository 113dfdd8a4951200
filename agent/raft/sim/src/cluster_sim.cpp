#include "swarmbox/raft/sim/cluster_sim.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "swarmbox/raft/message_codec.hpp"

namespace swarmbox::raft::sim {

std::uint64_t HashBytes(std::span<const std::uint8_t> bytes) {
  std::uint64_t h = 1469598103934665603ULL;
  for (std::uint8_t b : bytes) {
    h ^= b;
    h *= 1099511628211ULL;
  }
  return h;
}

namespace {

std::uint64_t EntryHash(const Entry& e) {
  return HashBytes(e.data) ^ (static_cast<std::uint64_t>(e.type) << 56);
}


std::unique_ptr<StateMachine> MakeMachine(SimMachine kind) {
  switch (kind) {
    case SimMachine::kMission:
      return std::make_unique<MissionStateMachine>();
    case SimMachine::kEntryLog:
      return std::make_unique<EntryLogMachine>();
  }
  SWARMBOX_CHECK(false);  // unknown SimMachine
  return nullptr;
}

std::int64_t Us(double seconds) { return static_cast<std::int64_t>(std::llround(seconds * 1e6)); }

std::uint64_t ConfHash(const ConfState& c) {
  Bytes b;
  for (NodeId v : c.voters) b.push_back(static_cast<std::uint8_t>(v));
  b.push_back(0xff);
  for (NodeId l : c.learners) b.push_back(static_cast<std::uint8_t>(l));
  return HashBytes(b);
}

}  // namespace

struct ClusterSim::Event {
  enum class Kind { kTick, kDeliver, kAction };
  std::int64_t at_us = 0;
  std::uint64_t seq = 0;
  Kind kind = Kind::kAction;
  int node = 0;  // tick: the node; deliver: the receiver
  int from = 0;
  std::uint32_t epoch = 0;
  Bytes bytes;
  std::function<void()> action;
};

bool ClusterSim::EventLater::operator()(const Event* a, const Event* b) const {
  if (a->at_us != b->at_us) return a->at_us > b->at_us;
  return a->seq > b->seq;
}

class ClusterSim::SimClock final : public Clock {
 public:
  explicit SimClock(const ClusterSim& sim) : sim_(sim) {}
  double NowS() const override { return sim_.now_s(); }

 private:
  const ClusterSim& sim_;
};

class ClusterSim::NodeTransport final : public Transport {
 public:
  NodeTransport(ClusterSim& sim, int node) : sim_(sim), node_(node) {}
  void Send(const std::string& to, std::span<const std::uint8_t> bytes) override {
    sim_.SendMessage(node_, to, bytes);
  }

 private:
  ClusterSim& sim_;
  int node_;
};

// The node's durable storage, with the Log Matching / Leader Append-Only checks on every write.
class ClusterSim::CheckedStorage final : public MemoryStorage {
 public:
  CheckedStorage(ClusterSim& sim, int node) : sim_(sim), node_(node) {}
  Status Save(const std::optional<HardState>& hard_state, std::span<const Entry> entries,
              const Snapshot& snapshot) override {
    sim_.OnSave(node_, hard_state, entries, snapshot);
    return MemoryStorage::Save(hard_state, entries, snapshot);
  }

 private:
  ClusterSim& sim_;
  int node_;
};

struct ClusterSim::Node {
  std::unique_ptr<CheckedStorage> storage;
  std::unique_ptr<NodeTransport> transport;
  std::unique_ptr<NodeDriver> driver;
  bool alive = false;
  std::uint32_t epoch = 0;
  int restarts = 0;
  std::uint64_t last_term = 0;
  NodeId last_vote = kNoNode;
  std::uint64_t checked_commit = 0;
  std::uint64_t checked_applied = 0;
  std::uint64_t tapped_last = 0;  // the last index the tap yielded in this life
  std::vector<Committed> tapped;  // scratch for TakeCommitted
  std::uint64_t led_term = 0;  // last term this node was seen leading
  ConfState conf_before;       // the node's configuration at its previous check
};

ClusterSim::ClusterSim(const SimConfig& config) : config_(config), rng_(config.seed) {
  SWARMBOX_CHECK(config.nodes >= 1 && config.nodes <= 200);
  SWARMBOX_CHECK(config.voters >= 0);
  report_.seed = config.seed;
  clock_ = std::make_unique<SimClock>(*this);
  group_.assign(static_cast<std::size_t>(config.nodes), 0);
  std::vector<std::string> names;
  for (int i = 0; i < config.nodes; ++i) names.push_back(Name(i));
  std::vector<std::pair<std::string, int>> sorted;
  for (int i = 0; i < config.nodes; ++i) sorted.emplace_back(Name(i), i);
  std::sort(sorted.begin(), sorted.end());
  for (const auto& [name, i] : sorted) node_of_id_.push_back(i);
  target_voters_ = static_cast<std::size_t>(
      config.voters > 0 && config.voters < config.nodes ? config.voters : config.nodes);
  std::sort(names.begin(), names.end());
  cluster_tag_ = ClusterTag(names);
  for (int i = 0; i < config.nodes; ++i) {
    auto n = std::make_unique<Node>();
    n->storage = std::make_unique<CheckedStorage>(*this, i);
    nodes_.push_back(std::move(n));
  }
  for (int i = 0; i < config.nodes; ++i) Restart(i);
  if (config.propose_interval_s > 0) ScheduleEvery(config_.propose_interval_s, &ClusterSim::ProposeRandom);
  ScheduleNextCrash();
  ScheduleNextPartition();
  for (double t : config.leader_crash_at_s) {
    auto* e = new Event;
    e->action = [this] { CrashLeaderNow(); };
    Schedule(Us(t), e);
  }
  for (double t : config.voter_crash_at_s) {
    auto* e = new Event;
    e->action = [this] { CrashVoterNow(); };
    Schedule(Us(t), e);
  }
  if (config.conf_change_interval_s > 0) ScheduleEvery(config_.conf_change_interval_s, &ClusterSim::RandomConfChange);
}

ClusterSim::~ClusterSim() {
  while (!queue_.empty()) {
    delete queue_.top();
    queue_.pop();
  }
}

double ClusterSim::Uniform(double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng_);
}

bool ClusterSim::Chance(double p) { return p > 0 && Uniform(0, 1) < p; }

void ClusterSim::Schedule(std::int64_t at_us, Event* e) {
  e->at_us = std::max(at_us, now_us_);
  e->seq = next_seq_++;
  queue_.push(e);
}

bool ClusterSim::alive(int node) const { return nodes_[static_cast<std::size_t>(node)]->alive; }

const NodeDriver* ClusterSim::driver(int node) const {
  return nodes_[static_cast<std::size_t>(node)]->driver.get();
}

const MemoryStorage& ClusterSim::storage(int node) const {
  return *nodes_[static_cast<std::size_t>(node)]->storage;
}

int ClusterSim::Leader() const {
  int best = -1;
  std::uint64_t best_term = 0;
  for (int i = 0; i < size(); ++i) {
    const NodeDriver* d = driver(i);
    if (d && d->is_leader() && d->raft().term() >= best_term) {
      best = i;
      best_term = d->raft().term();
    }
  }
  return best;
}

SimReport ClusterSim::TakeReport() { return std::move(report_); }

void ClusterSim::Violation(const std::string& property, const std::string& details) {
  std::ostringstream s;
  s << "seed=" << config_.seed << " nodes=" << config_.nodes << " t=" << now_s() << " "
    << property << ": " << details;
  report_.violations.push_back(s.str());
}

// --- nodes ---------------------------------------------------------------------------------------

void ClusterSim::Crash(int node) {
  Node& n = *nodes_[static_cast<std::size_t>(node)];
  if (!n.alive) return;
  n.alive = false;
  ++n.epoch;
  n.driver.reset();
  ++report_.crashes;
}

DriverConfig ClusterSim::DriverConfigOf(int node, int restarts) const {
  DriverConfig dc;
  dc.self = Name(node);
  for (int i = 0; i < size(); ++i) dc.members.push_back(Name(i));
  if (config_.voters > 0 && config_.voters < size()) {
    for (int i = 0; i < config_.voters; ++i) dc.voters.push_back(Name(i));
  }
  dc.learner_heartbeat_ms = config_.learner_heartbeat_ms;
  dc.voter_lost_ms = config_.voter_lost_ms;
  dc.tick_ms = config_.tick_ms;
  dc.heartbeat_ms = config_.heartbeat_ms;
  dc.election_timeout_ms = config_.election_timeout_ms;
  dc.pre_vote = config_.pre_vote;
  dc.check_quorum = config_.check_quorum;
  dc.snapshot_every_entries = config_.snapshot_every_entries;
  dc.seed = config_.seed * std::uint64_t{1000003} +
            static_cast<std::uint64_t>(node) * std::uint64_t{7919} +
            static_cast<std::uint64_t>(restarts);
  return dc;
}

void ClusterSim::Restart(int node) {
  Node& n = *nodes_[static_cast<std::size_t>(node)];
  if (n.alive) return;
  if (config_.faults.wipe_storage_on_restart && n.restarts > 0) {
    n.storage = std::make_unique<CheckedStorage>(*this, node);
    // The per-node term/vote memory goes too, so that what the checker reports is the damage to
    // the cluster (two leaders, lost commits), not the amnesia itself.
    n.last_term = 0;
    n.last_vote = kNoNode;
  }
  const DriverConfig dc = DriverConfigOf(node, n.restarts);
  ++n.restarts;
  n.transport = std::make_unique<NodeTransport>(*this, node);
  EventSink sink;
  if (config_.record_events) {
    sink = [this](const LogEvent& e) { report_.events.push_back(e.str()); };
  }
  auto d = NodeDriver::Open(dc, *n.storage, *n.transport, *clock_, sink,
                            MakeMachine(config_.machine));
  if (!d) {
    Violation("Restart", Name(node) + " failed to restart: " + d.error().ToString());
    return;
  }
  n.driver = std::move(*d);
  n.alive = true;
  ++n.epoch;
  n.checked_commit = n.driver->raft().log().snapshot_index();
  n.conf_before = n.driver->conf_state();
  n.checked_applied = 0;
  n.tapped_last = 0;
  // A random phase for the node's tick clock.
  auto* e = new Event;
  e->kind = Event::Kind::kTick;
  e->node = node;
  e->epoch = n.epoch;
  Schedule(now_us_ + static_cast<std::int64_t>(Uniform(0, config_.tick_ms * 1000.0)), e);
  CheckNode(node);
}

void ClusterSim::ScheduleTick(int node) {
  const Node& n = *nodes_[static_cast<std::size_t>(node)];
  auto* e = new Event;
  e->kind = Event::Kind::kTick;
  e->node = node;
  e->epoch = n.epoch;
  Schedule(now_us_ + config_.tick_ms * 1000LL, e);
}

void ClusterSim::Partition(const std::vector<std::vector<int>>& groups) {
  std::fill(group_.begin(), group_.end(), -1);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    for (int node : groups[g]) group_[static_cast<std::size_t>(node)] = static_cast<int>(g);
  }
  // Nodes not listed are isolated, each on its own.
  int next = static_cast<int>(groups.size());
  for (int& g : group_) {
    if (g < 0) g = next++;
  }
  ++report_.partitions;
}

void ClusterSim::Heal() { std::fill(group_.begin(), group_.end(), 0); }

Status ClusterSim::Propose(int node, const MissionCommand& command) {
  return Propose(node, EncodeCommand(command));
}

Status ClusterSim::ProposeConfChange(int node, ConfChangeOp op, int target) {
  Node& n = *nodes_[static_cast<std::size_t>(node)];
  if (!n.alive) return Error(ErrorCode::kUnavailable, Name(node) + " is down", "sim");
  Status s = n.driver->ProposeConfChange(op, Name(target));
  CheckNode(node);
  return s;
}

Status ClusterSim::Propose(int node, Bytes data) {
  Node& n = *nodes_[static_cast<std::size_t>(node)];
  if (!n.alive) return Error(ErrorCode::kUnavailable, Name(node) + " is down", "sim");
  const std::uint64_t h = HashBytes(data);
  proposed_at_us_.emplace(h, now_us_);
  ++report_.proposals;
  Status s = n.driver->Propose(std::move(data));
  if (!s) {
    ++report_.proposals_dropped;
    proposed_at_us_.erase(h);
  }
  CheckNode(node);
  return s;
}

// --- network -------------------------------------------------------------------------------------

void ClusterSim::SendMessage(int from, const std::string& to_name,
                             std::span<const std::uint8_t> bytes) {
  ++report_.messages_sent;
  const int to = std::stoi(to_name.substr(1)) - 1;
  const NodeDriver* sender = nodes_[static_cast<std::size_t>(from)]->driver.get();
  if (sender != nullptr && sender->is_leader()) {
    ++report_.leader_messages;
    report_.leader_burst_max = std::max(report_.leader_burst_max, ++leader_burst_);
  }
  if (bytes.size() > 5 && bytes[5] == static_cast<std::uint8_t>(MessageType::kSnap)) {
    ++report_.snapshots_sent;
  }
  if (group_[static_cast<std::size_t>(from)] != group_[static_cast<std::size_t>(to)]) return;
  if (drop_filter_) {
    auto m = DecodeMessage(bytes, cluster_tag_);
    if (!m) {
      Violation("Transport", Name(from) + " sent an undecodable message: " + m.error().ToString());
      return;
    }
    if (drop_filter_(from, to, *m)) return;
  }
  const NetworkModel& net = config_.net;
  const int copies = Chance(net.duplicate) ? 2 : 1;
  for (int c = 0; c < copies; ++c) {
    if (Chance(net.loss)) continue;
    double delay_ms = net.delay_ms + Uniform(-net.jitter_ms, net.jitter_ms);
    if (Chance(net.reorder)) delay_ms += Uniform(0, net.reorder_ms);
    auto* e = new Event;
    e->kind = Event::Kind::kDeliver;
    e->node = to;
    e->from = from;
    e->bytes.assign(bytes.begin(), bytes.end());
    Schedule(now_us_ + static_cast<std::int64_t>(std::max(0.0, delay_ms) * 1000.0), e);
  }
}

// --- faults and load -----------------------------------------------------------------------------

void ClusterSim::ScheduleNextCrash() {
  const FaultModel& f = config_.faults;
  if (f.crash_mean_interval_s <= 0) return;
  auto* e = new Event;
  e->action = [this] {
    const FaultModel& fm = config_.faults;
    int victim = -1;
    if (Chance(fm.crash_leader_bias)) victim = Leader();
    if (victim < 0) victim = static_cast<int>(rng_() % static_cast<std::uint64_t>(size()));
    int live = 0;
    for (int i = 0; i < size(); ++i) live += alive(i) ? 1 : 0;
    if (alive(victim) && live > 1) {
      if (victim == Leader()) ++report_.leader_crashes;
      Crash(victim);
      auto* r = new Event;
      r->action = [this, victim] { Restart(victim); };
      Schedule(now_us_ + Us(Uniform(fm.down_min_s, fm.down_max_s)), r);
    }
    ScheduleNextCrash();
  };
  Schedule(now_us_ + Us(std::exponential_distribution<double>(1.0 / f.crash_mean_interval_s)(rng_)),
           e);
}

void ClusterSim::ScheduleNextPartition() {
  const FaultModel& f = config_.faults;
  if (f.partition_mean_interval_s <= 0) return;
  auto* e = new Event;
  e->action = [this] {
    const FaultModel& fm = config_.faults;
    std::vector<int> order(static_cast<std::size_t>(size()));
    for (int i = 0; i < size(); ++i) order[static_cast<std::size_t>(i)] = i;
    std::shuffle(order.begin(), order.end(), rng_);
    const auto cut = 1 + static_cast<std::ptrdiff_t>(rng_() % static_cast<std::uint64_t>(size() - 1));
    Partition({std::vector<int>(order.begin(), order.begin() + cut),
               std::vector<int>(order.begin() + cut, order.end())});
    auto* h = new Event;
    h->action = [this] { Heal(); };
    Schedule(now_us_ + Us(Uniform(fm.partition_min_s, fm.partition_max_s)), h);
    ScheduleNextPartition();
  };
  Schedule(now_us_ +
               Us(std::exponential_distribution<double>(1.0 / f.partition_mean_interval_s)(rng_)),
           e);
}

void ClusterSim::ScheduleEvery(double interval_s, void (ClusterSim::*action)()) {
  auto* e = new Event;
  e->action = [this, interval_s, action] {
    (this->*action)();
    ScheduleEvery(interval_s, action);
  };
  Schedule(now_us_ + Us(interval_s * Uniform(0.5, 1.5)), e);
}

void ClusterSim::ProposeRandom() {
  std::vector<int> live;
  for (int i = 0; i < size(); ++i) {
    if (alive(i)) live.push_back(i);
  }
  if (live.empty()) return;
  const int node = live[rng_() % live.size()];
  const double r = Uniform(0, 1);
  const auto victim = static_cast<std::uint32_t>(1 + rng_() % 3);
  MissionCommand cmd;
  if (r < 0.05) {
    cmd = StartSearch{};
  } else if (r < 0.08) {
    AssignSectors a;
    for (int i = 0; i < size(); ++i) {
      a.sectors.push_back(Sector{Name(i), i * 50.0, 0.0, i * 50.0 + 50.0, 100.0});
    }
    cmd = a;
  } else if (r < 0.12) {
    cmd = ConvergeOn{victim};
  } else if (r < 0.15) {
    cmd = BeginRescue{victim, Name(size() - 1)};
  } else if (r < 0.18) {
    cmd = MarkRescued{victim};
  } else if (r < 0.20) {
    cmd = ConfirmVictim{"ground", Uniform(-200, 200), Uniform(-200, 200)};
  } else if (r < 0.205) {
    cmd = ReturnHome{};
  } else {
    // Sightings around a few spots, so that pairs confirm victims.
    const double cx = static_cast<double>(rng_() % 4) * 60.0;
    cmd = ReportSighting{Name(node), ++sighting_seq_, cx + Uniform(-4, 4), Uniform(-4, 4),
                         Uniform(0.4, 1.0)};
  }
  (void)Propose(node, cmd);
}

void ClusterSim::CrashLeaderNow() {
  const int leader = Leader();
  if (leader < 0) {
    ++report_.failovers_missed;
    return;
  }
  if (leader_crash_us_) ++report_.failovers_missed;
  leader_crash_us_ = now_us_;
  crashed_leader_term_ = driver(leader)->raft().term();
  ++report_.leader_crashes;
  Crash(leader);
  auto* r = new Event;
  r->action = [this, leader] { Restart(leader); };
  Schedule(now_us_ + Us(config_.leader_down_s), r);
}

void ClusterSim::CrashVoterNow() {
  if (voter_crash_us_) ++report_.replacements_missed;
  voter_crash_us_.reset();
  const int leader = Leader();
  if (leader < 0) {
    ++report_.replacements_missed;
    return;
  }
  std::vector<int> candidates;
  for (NodeId v : driver(leader)->conf_state().voters) {
    const int node = NodeOf(v);
    if (node != leader && alive(node)) candidates.push_back(node);
  }
  if (candidates.empty()) {
    ++report_.replacements_missed;
    return;
  }
  const int victim = candidates[rng_() % candidates.size()];
  voter_crash_us_ = now_us_;
  crashed_voter_ = driver(victim)->raft().id();
  Crash(victim);
  auto* r = new Event;
  r->action = [this, victim] { Restart(victim); };
  Schedule(now_us_ + Us(config_.voter_down_s), r);
}

void ClusterSim::RandomConfChange() {
  const int leader = Leader();
  if (leader < 0) return;
  const ConfState conf = driver(leader)->conf_state();
  const NodeId self = driver(leader)->raft().id();
  std::vector<NodeId> others;  // voters but the leader
  for (NodeId v : conf.voters) {
    if (v != self) others.push_back(v);
  }
  std::vector<NodeId> outside;
  for (NodeId id = 1; id <= static_cast<NodeId>(size()); ++id) {
    if (!IsVoter(conf, id) && !IsLearner(conf, id)) outside.push_back(id);
  }
  auto pick = [this](const std::vector<NodeId>& v) { return v[rng_() % v.size()]; };
  const auto op = rng_() % 4;
  if (op == 0 && !others.empty()) {
    (void)ProposeConfChange(leader, ConfChangeOp::kRemoveNode, NodeOf(pick(others)));
  } else if (op == 1 && !conf.learners.empty()) {
    (void)ProposeConfChange(leader, ConfChangeOp::kPromoteLearner, NodeOf(pick(conf.learners)));
  } else if (op == 2 && !conf.learners.empty()) {
    (void)ProposeConfChange(leader, ConfChangeOp::kRemoveNode, NodeOf(pick(conf.learners)));
  } else if (op == 3 && !outside.empty()) {
    (void)ProposeConfChange(leader, ConfChangeOp::kAddLearner, NodeOf(pick(outside)));
  }
}

// --- the event loop ------------------------------------------------------------------------------

void ClusterSim::Step() {
  Event* e = queue_.top();
  queue_.pop();
  std::unique_ptr<Event> owned(e);
  now_us_ = e->at_us;
  leader_burst_ = 0;
  switch (e->kind) {
    case Event::Kind::kTick: {
      Node& n = *nodes_[static_cast<std::size_t>(e->node)];
      if (!n.alive || n.epoch != e->epoch) return;
      (void)n.driver->Tick();
      CheckNode(e->node);
      ScheduleTick(e->node);
      return;
    }
    case Event::Kind::kDeliver: {
      Node& n = *nodes_[static_cast<std::size_t>(e->node)];
      if (!n.alive) return;
      if (group_[static_cast<std::size_t>(e->from)] != group_[static_cast<std::size_t>(e->node)]) {
        return;
      }
      ++report_.messages_delivered;
      Status s = n.driver->Receive(e->bytes);
      if (!s && s.error().code() == ErrorCode::kProtocol) {
        Violation("Transport", Name(e->node) + " rejected a message: " + s.error().ToString());
      }
      CheckNode(e->node);
      return;
    }
    case Event::Kind::kAction:
      e->action();
      return;
  }
}

void ClusterSim::RunFor(double seconds) {
  const std::int64_t end = now_us_ + Us(seconds);
  while (!queue_.empty() && queue_.top()->at_us <= end && report_.violations.empty()) Step();
  if (report_.violations.empty()) now_us_ = end;
}

int ClusterSim::RunUntilLeader(double max_s) {
  const std::int64_t end = now_us_ + Us(max_s);
  while (Leader() < 0 && !queue_.empty() && queue_.top()->at_us <= end &&
         report_.violations.empty()) {
    Step();
  }
  return Leader();
}

// --- safety checks -------------------------------------------------------------------------------

void ClusterSim::OnSave(int node, const std::optional<HardState>& hs,
                        std::span<const Entry> entries, const Snapshot& snapshot) {
  (void)hs;
  const Node& n = *nodes_[static_cast<std::size_t>(node)];
  const MemoryStorage& st = *n.storage;
  const NodeDriver* d = n.driver.get();  // null while the driver is being opened
  if (d && d->is_leader()) {
    // Leader Append-Only (Raft §5.3): a leader never overwrites or deletes entries in its log.
    if (!snapshot.empty()) Violation("Leader Append-Only", Name(node) + " installs a snapshot");
    if (!entries.empty() && entries.front().index != st.last_index() + 1) {
      Violation("Leader Append-Only",
                Name(node) + " term " + std::to_string(d->raft().term()) + " writes entry " +
                    std::to_string(entries.front().index) + " over a log ending at " +
                    std::to_string(st.last_index()));
    }
    CheckOneChangeAtATime(node, *d, entries);
  }
  CheckLogMatching(node, st, entries, snapshot);
}

void ClusterSim::CheckOneChangeAtATime(int node, const NodeDriver& d,
                                       std::span<const Entry> entries) {
  // One Change at a Time (thesis §4.1): no second change above the applied index, and none
  // before the leader applied an entry of its own term.
  const RaftLog& log = d.raft().log();
  for (const Entry& e : entries) {
    if (e.type != EntryType::kConfChange) continue;
    if (log.Term(log.applied()) != d.raft().term()) {
      Violation("One Change at a Time", Name(node) + " appends a change at " + std::to_string(e.index) +
                                            " before applying an entry of its term " +
                                            std::to_string(d.raft().term()));
    }
    for (std::uint64_t i = log.applied() + 1; i < e.index; ++i) {
      if (i >= log.first_index() && log.At(i).type == EntryType::kConfChange) {
        Violation("One Change at a Time", Name(node) + " appends a change at " + std::to_string(e.index) +
                                              " with another one in flight at " + std::to_string(i));
      }
    }
  }
}

void ClusterSim::CheckLogMatching(int node, const MemoryStorage& st, std::span<const Entry> entries,
                                  const Snapshot& snapshot) {
  if (entries.empty()) return;
  std::optional<std::uint64_t> prev;
  const std::uint64_t first = entries.front().index;
  if (!snapshot.empty()) {
    if (first - 1 == snapshot.index) prev = snapshot.term;
  } else {
    prev = st.Term(first - 1);
  }
  if (!prev) {
    Violation("Log Matching", Name(node) + " writes entry " + std::to_string(first) +
                                  " after a gap in its log");
    return;
  }
  // Log Matching (Raft §5.3): same index and term => same entry, preceded by the same term (so,
  // by induction, identical logs up to there).
  for (const Entry& e : entries) {
    if (e.term < *prev) {
      Violation("Log Matching", Name(node) + " entry " + std::to_string(e.index) + " term " +
                                    std::to_string(e.term) + " follows term " +
                                    std::to_string(*prev));
    }
    const EntryFact fact{*prev, EntryHash(e)};
    auto [it, inserted] = entries_seen_.emplace(std::make_pair(e.index, e.term), fact);
    if (!inserted && (it->second.prev_term != fact.prev_term ||
                      it->second.data_hash != fact.data_hash)) {
      Violation("Log Matching", Name(node) + " holds a different entry at index " +
                                    std::to_string(e.index) + " term " + std::to_string(e.term));
    }
    prev = e.term;
  }
}

void ClusterSim::CheckNode(int node) {
  Node& n = *nodes_[static_cast<std::size_t>(node)];
  if (!n.alive || !n.driver) return;
  const NodeDriver& d = *n.driver;
  if (d.stopped()) {
    Violation("Storage", Name(node) + " stopped: " + d.stop_error()->ToString());
    return;
  }
  const RawNode& raw = d.raft();
  const std::string who = Name(node);
  CheckTermAndVote(n, raw, who);
  CheckCommits(n, raw, who);
  CheckLeader(n, raw, who);
  CheckStateMachine(n, d, who);
  CheckTap(node);
}

void ClusterSim::CheckTermAndVote(Node& n, const RawNode& raw, const std::string& who) {
  // Terms never go back; one vote per term (Raft §5.2), across restarts too.
  if (raw.term() < n.last_term) {
    Violation("Election Safety", who + " term went back from " + std::to_string(n.last_term) +
                                     " to " + std::to_string(raw.term()));
  } else if (raw.term() > n.last_term) {
    n.last_term = raw.term();
    n.last_vote = raw.vote();
  } else if (raw.vote() != n.last_vote) {
    if (n.last_vote != kNoNode) {
      Violation("Election Safety", who + " voted for " + std::to_string(n.last_vote) + " and " +
                                       std::to_string(raw.vote()) + " in term " +
                                       std::to_string(raw.term()));
    }
    n.last_vote = raw.vote();
  }
}

void ClusterSim::CheckCommits(Node& n, const RawNode& raw, const std::string& who) {
  const RaftLog& log = raw.log();
  // Commits: every node commits the same entry at each index.
  const std::uint64_t commit = log.committed();
  const std::uint64_t snap = log.snapshot_index();
  if (snap > 0 && snap <= committed_.size() && committed_[snap - 1].term != 0 &&
      committed_[snap - 1].term != log.snapshot_term()) {
    Violation("State Machine Safety", who + " snapshot at " + std::to_string(snap) + " has term " +
                                          std::to_string(log.snapshot_term()));
  }
  for (std::uint64_t i = std::max(n.checked_commit, snap) + 1; i <= commit; ++i) {
    const Entry& e = log.At(i);
    const CommitFact fact{e.term, EntryHash(e), e.type == EntryType::kNormal};
    if (committed_.size() < i) committed_.resize(i, CommitFact{0, 0, false});
    CommitFact& known = committed_[i - 1];
    if (known.term == 0) {
      known = fact;
      if (e.type == EntryType::kConfChange) ++report_.conf_changes;
      if (raw.role() == Role::kLeader) CheckCommitQuorum(raw, n.conf_before, i, e);
      auto p = proposed_at_us_.find(fact.data_hash);
      if (p != proposed_at_us_.end()) {
        report_.commit_ms.push_back(static_cast<double>(now_us_ - p->second) / 1000.0);
        proposed_at_us_.erase(p);
      }
    } else if (known.term != fact.term || known.data_hash != fact.data_hash) {
      Violation("State Machine Safety",
                who + " commits a different entry at index " + std::to_string(i) + " (term " +
                    std::to_string(fact.term) + ", first committed in term " +
                    std::to_string(known.term) + ")");
    }
  }
  n.checked_commit = std::max(n.checked_commit, commit);
  n.conf_before = raw.conf_state();
  report_.max_commit = std::max(report_.max_commit, commit);
}

void ClusterSim::CheckLeader(Node& n, const RawNode& raw, const std::string& who) {
  // Election Safety (Raft §5.2) and Leader Completeness (§5.4) when a node starts to lead.
  if (raw.role() == Role::kLeader && !raw.is_voter()) {
    Violation("Configuration", who + " leads term " + std::to_string(raw.term()) + " but is no voter");
  }
  if (raw.invalid_conf_changes() != 0) {
    Violation("Configuration", who + " committed a membership change that does not apply");
  }
  if (raw.role() == Role::kLeader && voter_crash_us_ && !IsVoter(raw.conf_state(), crashed_voter_) &&
      raw.conf_state().voters.size() >= target_voters_) {
    report_.replacement_ms.push_back(static_cast<double>(now_us_ - *voter_crash_us_) / 1000.0);
    voter_crash_us_.reset();
  }
  if (raw.role() == Role::kLeader && n.led_term != raw.term()) {
    n.led_term = raw.term();
    auto [it, inserted] = leader_of_term_.emplace(raw.term(), raw.id());
    if (!inserted && it->second != raw.id()) {
      Violation("Election Safety", "two leaders in term " + std::to_string(raw.term()) + ": " +
                                       Name(NodeOf(it->second)) + " and " + who);
    }
    if (inserted) {
      ++report_.leader_terms;
      if (leader_crash_us_ && raw.term() > crashed_leader_term_) {
        report_.failover_ms.push_back(static_cast<double>(now_us_ - *leader_crash_us_) / 1000.0);
        leader_crash_us_.reset();
      }
    }
    CheckLeaderCompleteness(raw, who);
  }
}

void ClusterSim::CheckLeaderCompleteness(const RawNode& raw, const std::string& who) {
  const RaftLog& log = raw.log();
  const std::uint64_t snap = log.snapshot_index();
  for (std::uint64_t i = snap + 1; i <= committed_.size(); ++i) {
    const CommitFact& known = committed_[i - 1];
    if (known.term == 0) continue;
    if (i > log.last_index() || log.At(i).term != known.term ||
        EntryHash(log.At(i)) != known.data_hash) {
      Violation("Leader Completeness", who + " leads term " + std::to_string(raw.term()) +
                                           " without committed entry " + std::to_string(i));
      break;
    }
  }
}

void ClusterSim::CheckStateMachine(Node& n, const NodeDriver& d, const std::string& who) {
  const RaftLog& log = d.raft().log();
  // State Machine Safety (Raft §5.4.3): the same state after applying the same index.
  if (d.applied_index() != log.applied()) {
    Violation("State Machine Safety", who + " state machine applied " +
                                          std::to_string(d.applied_index()) +
                                          " but raft applied " + std::to_string(log.applied()));
  }
  if (const MissionState* m = d.FindMission(); m != nullptr && m->applied_index() != log.applied()) {
    Violation("State Machine Safety", who + " mission applied " +
                                          std::to_string(m->applied_index()) + " but raft applied " +
                                          std::to_string(log.applied()));
  }
  if (d.applied_index() != n.checked_applied) {
    n.checked_applied = d.applied_index();
    // The machine's state and the membership (Configuration) after the same index.
    const std::uint64_t h = HashBytes(d.machine().Snapshot()) ^ (ConfHash(d.conf_state()) * 31);
    auto [it, inserted] = state_hash_at_.emplace(d.applied_index(), h);
    if (!inserted && it->second != h) {
      Violation("State Machine Safety", who + " state after index " +
                                            std::to_string(d.applied_index()) + " differs");
    }
  }
}

void ClusterSim::CheckTap(int node) {
  Node& n = *nodes_[static_cast<std::size_t>(node)];
  const std::string who = Name(node);
  n.driver->TakeCommitted(&n.tapped);
  report_.entries_tapped += n.tapped.size();
  const bool complete = config_.machine == SimMachine::kEntryLog;
  for (const Committed& c : n.tapped) {
    if (c.index <= n.tapped_last || c.index > n.driver->applied_index()) {
      Violation("Committed Tap", who + " tapped index " + std::to_string(c.index) + " after " +
                                     std::to_string(n.tapped_last) + " with " +
                                     std::to_string(n.driver->applied_index()) + " applied");
      return;
    }
    // Every node taps the same data at an index.
    auto [seen, first] = tapped_hash_at_.emplace(c.index, HashBytes(c.data));
    if (!first && seen->second != HashBytes(c.data)) {
      Violation("Committed Tap", who + " tapped other data at index " + std::to_string(c.index) +
                                     " than another node");
      return;
    }
    // A node that compacts right after committing can take indices into its snapshot before any
    // node's commit of them was seen: those are checked against the other taps only.
    const CommitFact* known = c.index <= committed_.size() ? &committed_[c.index - 1] : nullptr;
    if (known != nullptr && known->term != 0 && known->data_hash != HashBytes(c.data)) {
      Violation("Committed Tap", who + " tapped other data than was committed at index " +
                                     std::to_string(c.index));
      return;
    }
    // The entry log replays the whole log: nothing but no-ops between two tapped entries.
    if (const std::uint64_t skipped = complete ? SkippedApplication(n.tapped_last, c.index) : 0; skipped != 0) {
      Violation("Committed Tap", who + " skipped committed entry " + std::to_string(skipped) +
                                     " (tapped " + std::to_string(c.index) + " after " +
                                     std::to_string(n.tapped_last) + ")");
      return;
    }
    n.tapped_last = c.index;
  }
}

std::uint64_t ClusterSim::SkippedApplication(std::uint64_t after, std::uint64_t before) const {
  for (std::uint64_t i = after + 1; i < before && i <= committed_.size(); ++i) {
    const CommitFact& gap = committed_[i - 1];
    if (gap.term != 0 && gap.application) return i;
  }
  return 0;
}

void ClusterSim::CheckCommitQuorum(const RawNode& leader, const ConfState& before, std::uint64_t index,
                                   const Entry& e) {
  // A step applies at most one change (the next is proposed only once it is applied, and commits
  // only in a later step), so the commit was made under the configuration before the step or the
  // one after it.
  std::string held;
  for (const ConfState* conf : {&before, &leader.conf_state()}) {
    std::size_t holding = 0;
    for (NodeId v : conf->voters) {
      const MemoryStorage& st = *nodes_[static_cast<std::size_t>(NodeOf(v))]->storage;
      if (index < st.state().snapshot.index || st.Term(index) == e.term) ++holding;
    }
    if (!conf->voters.empty() && holding >= conf->voters.size() / 2 + 1) return;
    held += (held.empty() ? "" : ", ") + std::to_string(holding) + " of " + std::to_string(conf->voters.size());
  }
  Violation("Commit Quorum", Name(NodeOf(leader.id())) + " commits index " + std::to_string(index) +
                                 " held by " + held + " voters (configuration before, after the step)");
}

SimReport RunSimulation(const SimConfig& config) {
  ClusterSim sim(config);
  sim.RunFor(config.duration_s);
  return sim.TakeReport();
}

}  // namespace swarmbox::raft::sim
