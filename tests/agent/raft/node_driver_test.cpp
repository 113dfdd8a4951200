// NodeDriver: persistence before sending, contract events, restart, stop-loudly on storage
// failure, misaddressed and garbage input, configuration errors; any state machine (the entry
// log) and the committed-entries tap with its replay after a restart or a snapshot.
#include "swarmbox/raft/node_driver.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <deque>
#include <filesystem>
#include <map>
#include <set>

#include "swarmbox/raft/sim/memory_storage.hpp"
#include "swarmbox/raft/wal_storage.hpp"

namespace swarmbox::raft {
namespace {

using sim::MemoryStorage;

class FakeClock final : public Clock {
 public:
  double NowS() const override { return t_s; }
  double t_s = 0;
};

struct Packet {
  std::string from, to;
  Bytes bytes;
};

class FakeRadio final : public Transport {
 public:
  FakeRadio(std::string self, std::deque<Packet>* air) : self_(std::move(self)), air_(air) {}
  void Send(const std::string& to, std::span<const std::uint8_t> bytes) override {
    air_->push_back(Packet{self_, to, Bytes(bytes.begin(), bytes.end())});
    ++sent;
  }
  int sent = 0;

 private:
  std::string self_;
  std::deque<Packet>* air_;
};

DriverConfig Cfg(const std::string& self, std::vector<std::string> members) {
  DriverConfig c;
  c.self = self;
  c.members = std::move(members);
  c.seed = 7;
  c.snapshot_every_entries = 4;
  return c;
}

// Three drones on a perfect radio, each with its own MemoryStorage.
class DriverCluster : public ::testing::Test {
 protected:
  const std::vector<std::string> names_ = {"scout_1", "scout_2", "lifter"};

  void SetUp() override {
    for (const auto& n : names_) Start(n);
  }
  void Start(const std::string& name) {
    radios_[name] = std::make_unique<FakeRadio>(name, &air_);
    std::unique_ptr<StateMachine> machine;
    if (entry_log_) machine = std::make_unique<EntryLogMachine>();
    auto d = NodeDriver::Open(Cfg(name, names_), storage_[name], *radios_[name], clock_,
                              [this](const LogEvent& e) { events_.push_back(e.str()); },
                              std::move(machine));
    ASSERT_TRUE(d.ok()) << d.error().ToString();
    drivers_[name] = std::move(*d);
  }
  void Pump() {
    while (!air_.empty()) {
      Packet p = air_.front();
      air_.pop_front();
      if (cut_.count(p.from) != 0 || cut_.count(p.to) != 0) continue;  // off the radio
      auto it = drivers_.find(p.to);
      if (it == drivers_.end() || !it->second) continue;
      (void)it->second->Receive(p.bytes);
    }
  }
  void TickAll(int n) {
    for (int i = 0; i < n; ++i) {
      clock_.t_s += 0.05;
      for (auto& [name, d] : drivers_) {
        if (d) (void)d->Tick();
      }
      Pump();
    }
  }
  std::string Leader() {
    for (auto& [name, d] : drivers_) {
      if (d && d->is_leader()) return name;
    }
    return "";
  }
  std::vector<LogfmtFields> Events(const std::string& event) {
    std::vector<LogfmtFields> out;
    for (const auto& line : events_) {
      auto f = ParseLogfmt(line);
      if (FindField(f, "event") == event) out.push_back(f);
    }
    return out;
  }

  std::vector<Committed> Take(const std::string& name) {
    std::vector<Committed> out;
    drivers_[name]->TakeCommitted(&out);
    return out;
  }
  std::string AFollower() {
    const std::string leader = Leader();
    return names_[0] == leader ? names_[1] : names_[0];
  }

  bool entry_log_ = false;     // the drones' machine: EntryLogMachine, else the default mission
  std::set<std::string> cut_;  // drones whose packets are lost
  FakeClock clock_;
  std::deque<Packet> air_;
  std::map<std::string, MemoryStorage> storage_;
  std::map<std::string, std::unique_ptr<FakeRadio>> radios_;
  std::map<std::string, std::unique_ptr<NodeDriver>> drivers_;
  std::vector<std::string> events_;
};

TEST_F(DriverCluster, ElectsLeaderAndEveryDronePrintsContractEvents) {
  TickAll(40);
  const std::string leader = Leader();
  ASSERT_FALSE(leader.empty());
  auto elected = Events("leader_elected");
  ASSERT_EQ(elected.size(), 3u);
  for (const auto& f : elected) {
    EXPECT_EQ(FindField(f, "leader"), leader);
    EXPECT_TRUE(FindField(f, "term").has_value());
  }
  // A follower's proposal is forwarded to the leader and committed everywhere.
  ASSERT_TRUE(drivers_["scout_2"]->Propose(StartSearch{}).ok());
  Pump();
  // (An operator's word: since #19 one sighting never confirms a victim on its own.)
  ASSERT_TRUE(drivers_["scout_1"]->Propose(ConfirmVictim{"scout_1", 41.5, -12}).ok());
  Pump();
  TickAll(2);  // commit index reaches the followers
  for (const auto& n : names_) {
    EXPECT_EQ(drivers_[n]->mission().phase(), MissionPhase::kSearch) << n;
    ASSERT_EQ(drivers_[n]->mission().victims().size(), 1u) << n;
  }
  auto states = Events("mission_state");
  ASSERT_EQ(states.size(), 3u);
  std::set<std::string> nodes;
  for (const auto& f : states) {
    EXPECT_EQ(FindField(f, "state"), "SEARCH");
    EXPECT_EQ(FindField(f, "index"), FindField(states[0], "index"));
    nodes.insert(*FindField(f, "node"));
  }
  EXPECT_EQ(nodes.size(), 3u);
  auto victims = Events("victim_confirmed");
  ASSERT_EQ(victims.size(), 3u);
  EXPECT_EQ(FindField(victims[0], "id"), "1");
  EXPECT_EQ(FindField(victims[0], "x"), "41.500");
  EXPECT_EQ(FindField(victims[0], "y"), "-12.000");
}

TEST_F(DriverCluster, RestartedDroneRejoinsWithItsState) {
  TickAll(40);
  ASSERT_FALSE(Leader().empty());
  ASSERT_TRUE(drivers_[Leader()]->Propose(StartSearch{}).ok());
  for (std::uint64_t s = 1; s <= 10; ++s) {
    ASSERT_TRUE(drivers_[Leader()]->Propose(ReportSighting{"scout_2", s, 10.0 * static_cast<double>(s), 0, 0.6}).ok());
    Pump();
  }
  TickAll(2);
  std::string follower = names_[0] == Leader() ? names_[1] : names_[0];
  const MissionState before = drivers_[follower]->mission();
  const std::uint64_t term = drivers_[follower]->raft().term();
  EXPECT_GT(storage_[follower].state().snapshot.index, 0u);  // compacted (every 4 entries)
  drivers_[follower].reset();  // crash
  Start(follower);             // restart on the same storage
  EXPECT_EQ(drivers_[follower]->raft().term(), term);
  EXPECT_EQ(drivers_[follower]->mission(), before);
  TickAll(3);
  EXPECT_EQ(drivers_[follower]->leader(), Leader());
}

TEST_F(DriverCluster, StorageFailureStopsTheNodeLoudlyBeforeSending) {
  TickAll(40);
  const std::string leader = Leader();
  ASSERT_FALSE(leader.empty());
  std::string follower = names_[0] == leader ? names_[1] : names_[0];
  storage_[follower].FailNextSave(Error(ErrorCode::kIo, "fsync: Input/output error", "/data/wal"));
  const int sent_before = radios_[follower]->sent;
  ASSERT_TRUE(drivers_[leader]->Propose(StartSearch{}).ok());
  // Deliver the append to the failing follower by hand to see its result.
  Status last = Ok{};
  while (!air_.empty()) {
    Packet p = air_.front();
    air_.pop_front();
    Status s = drivers_[p.to]->Receive(p.bytes);
    if (p.to == follower && !s.ok()) last = s;
  }
  ASSERT_FALSE(last.ok());
  EXPECT_EQ(last.error().code(), ErrorCode::kIo);
  EXPECT_EQ(last.error().ToString(),
            "/data/wal: raft storage failed, node stopped: fsync: Input/output error");
  EXPECT_TRUE(drivers_[follower]->stopped());
  // The acknowledgement of the entries that were not made durable was never sent.
  EXPECT_EQ(radios_[follower]->sent, sent_before);
  auto stopped = Events("raft_stopped");
  ASSERT_EQ(stopped.size(), 1u);
  EXPECT_EQ(FindField(stopped[0], "node"), follower);
  // Every later call reports the same failure.
  Status t = drivers_[follower]->Tick();
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.error().message(), last.error().message());
}

TEST_F(DriverCluster, GarbageAndMisaddressedBytesAreReportedAndIgnored) {
  TickAll(40);
  const Bytes junk = {1, 2, 3, 4, 5};
  Status s = drivers_["scout_1"]->Receive(junk);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code(), ErrorCode::kProtocol);
  // A heartbeat meant for another drone.
  ASSERT_TRUE(drivers_[Leader()]->Tick().ok());
  ASSERT_TRUE(drivers_[Leader()]->Tick().ok());
  ASSERT_FALSE(air_.empty());
  Packet p = air_.front();
  air_.clear();
  const std::string wrong = p.to == "scout_1" ? "scout_2" : "scout_1";
  if (wrong != Leader()) {
    s = drivers_[wrong]->Receive(p.bytes);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message().find("delivered to " + wrong), std::string::npos);
  }
  EXPECT_FALSE(drivers_["scout_1"]->stopped());
  TickAll(5);
  EXPECT_FALSE(Leader().empty());
}

// A mission follower cut off while the leader compacts gets the leader's snapshot: it prints
// the mission_state line for it, and its tap yields nothing for what the snapshot covers.
TEST_F(DriverCluster, InstalledMissionSnapshotIsAnnouncedAndTapsOnlyLaterEntries) {
  TickAll(40);
  const std::string leader = Leader();
  ASSERT_FALSE(leader.empty());
  const std::string follower = AFollower();
  TickAll(1);
  (void)Take(follower);
  cut_.insert(follower);
  ASSERT_TRUE(drivers_[leader]->Propose(StartSearch{}).ok());
  for (std::uint64_t s = 1; s <= 9; ++s) {
    ASSERT_TRUE(drivers_[leader]->Propose(ReportSighting{"scout_2", s, 10.0 * static_cast<double>(s), 0, 0.6}).ok());
    Pump();
  }
  TickAll(2);
  EXPECT_EQ(Take(follower).size(), 0u);  // heard nothing
  cut_.clear();
  events_.clear();
  TickAll(4);
  EXPECT_EQ(drivers_[follower]->mission(), drivers_[leader]->mission());
  const std::uint64_t snap = storage_[follower].state().snapshot.index;
  ASSERT_GT(snap, 0u);
  std::vector<std::string> from_snapshot;
  for (const auto& line : events_) {
    if (line.find("from=snapshot") != std::string::npos) from_snapshot.push_back(line);
  }
  ASSERT_EQ(from_snapshot.size(), 1u);
  EXPECT_NE(from_snapshot[0].find("node=" + follower + " event=mission_state state=SEARCH index=" +
                                  std::to_string(snap) + " from=snapshot"),
            std::string::npos)
      << from_snapshot[0];
  for (const Committed& c : Take(follower)) EXPECT_GT(c.index, snap);
}

// The entry log through the driver: every drone's tap yields the same entries in index order,
// once each; empty proposals are refused.
TEST_F(DriverCluster, EntryLogCommitsBytesAndEveryTapYieldsThemInOrder) {
  entry_log_ = true;
  drivers_.clear();
  for (const auto& n : names_) Start(n);
  TickAll(40);
  const std::string leader = Leader();
  ASSERT_FALSE(leader.empty());
  const std::string follower = AFollower();
  for (const auto& n : names_) EXPECT_EQ(drivers_[n]->leader(), leader) << n;
  EXPECT_EQ(drivers_[leader]->FindMission(), nullptr);
  Status empty = drivers_[follower]->Propose(Bytes{});
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.error().code(), ErrorCode::kInvalidArgument);
  ASSERT_TRUE(drivers_[follower]->Propose(Bytes{'p', 'o', 's'}).ok());  // forwarded
  Pump();
  ASSERT_TRUE(drivers_[leader]->Propose(Bytes{'a', 'r', 'r'}).ok());
  Pump();
  TickAll(2);
  const std::vector<Committed> want = Take(leader);
  ASSERT_EQ(want.size(), 2u);
  EXPECT_EQ(want[0].data, (Bytes{'p', 'o', 's'}));
  EXPECT_EQ(want[1].data, (Bytes{'a', 'r', 'r'}));
  EXPECT_LT(want[0].index, want[1].index);
  for (const auto& n : names_) {
    if (n != leader) {
      EXPECT_EQ(Take(n), want) << n;
    }
    EXPECT_TRUE(Take(n).empty()) << n;  // taken: nothing new since
  }
  EXPECT_EQ(events_.size(), 3u) << "leader_elected only: the entry log prints nothing";
}

// A restarted drone replays the whole log to its tap (snapshot first, then the WAL's entries);
// one cut off while the leader compacted gets a snapshot and taps exactly what it missed.
TEST_F(DriverCluster, EntryLogTapReplaysTheWholeLogAfterRestartAndSnapshot) {
  entry_log_ = true;
  drivers_.clear();
  for (const auto& n : names_) Start(n);
  TickAll(40);
  const std::string leader = Leader();
  ASSERT_FALSE(leader.empty());
  const std::string follower = AFollower();
  const std::string other = names_[2] == leader ? names_[1] == follower ? names_[0] : names_[1] : names_[2];
  auto propose = [&](int from, int to) {
    for (int k = from; k <= to; ++k) {
      ASSERT_TRUE(drivers_[leader]->Propose(Bytes{'e', static_cast<std::uint8_t>(k)}).ok());
      Pump();
    }
    TickAll(2);
  };
  propose(1, 5);
  const std::vector<Committed> first = Take(follower);
  ASSERT_EQ(first.size(), 5u);
  (void)Take(other);

  // Restart: the tap replays everything, in order, though the log was compacted (every 4).
  drivers_[follower].reset();
  Start(follower);
  EXPECT_GT(storage_[follower].state().snapshot.index, 0u);
  EXPECT_EQ(Take(follower), first);

  // Cut off while 10 more entries commit and the leader compacts past them: a snapshot.
  cut_.insert(other);
  propose(6, 15);
  // The leader no longer holds the entries after `other`'s last one: only a snapshot helps.
  ASSERT_GT(drivers_[leader]->raft().log().snapshot_index(), first.back().index);
  cut_.clear();
  TickAll(4);
  std::vector<Committed> all = Take(leader);
  ASSERT_EQ(all.size(), 15u);
  const std::vector<Committed> missed(all.begin() + 5, all.end());
  EXPECT_EQ(Take(other), missed);
  EXPECT_GT(storage_[other].state().snapshot.index, first.back().index);
  EXPECT_EQ(drivers_[other]->applied_index(), drivers_[leader]->applied_index());
  EXPECT_EQ(drivers_[other]->machine().Snapshot(), drivers_[leader]->machine().Snapshot());
}

// A node whose application reads only the state keeps no tap.
TEST(NodeDriver, TapOffKeepsNothing) {
  MemoryStorage st;
  std::deque<Packet> air;
  FakeRadio radio("solo", &air);
  FakeClock clock;
  DriverConfig c = Cfg("solo", {"solo"});
  c.tap_committed = false;
  auto d = NodeDriver::Open(c, st, radio, clock, nullptr);
  ASSERT_TRUE(d.ok());
  for (int i = 0; i < 30 && !(*d)->is_leader(); ++i) ASSERT_TRUE((*d)->Tick().ok());
  ASSERT_TRUE((*d)->Propose(StartSearch{}).ok());
  EXPECT_EQ((*d)->mission().phase(), MissionPhase::kSearch);
  std::vector<Committed> got = {Committed{99, Bytes{1}}};
  (*d)->TakeCommitted(&got);
  EXPECT_TRUE(got.empty());
}

TEST(NodeDriver, ConfigurationErrorsNameTheProblem) {
  MemoryStorage st;
  std::deque<Packet> air;
  FakeRadio radio("x", &air);
  FakeClock clock;
  auto d = NodeDriver::Open(Cfg("x", {"a", "b"}), st, radio, clock, nullptr);
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error().message(), "self 'x' is not among the members");
  DriverConfig c = Cfg("a", {"a", "b", "c"});
  c.heartbeat_ms = 75;
  d = NodeDriver::Open(c, st, radio, clock, nullptr);
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error().message(),
            "heartbeat_ms (75) and election_timeout_ms (500) must be multiples of tick_ms (50)");
  d = NodeDriver::Open(Cfg("a", {"a", "a"}), st, radio, clock, nullptr);
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error().message(), "member names must be distinct");
}

// End to end on real files: a single-drone cluster commits, restarts from its WAL and snapshot.
TEST(NodeDriver, SingleDroneRestartsFromWalOnDisk) {
  std::string tmpl = (std::filesystem::temp_directory_path() / "swarmbox-drv-XXXXXX").string();
  ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
  PosixFileSystem fs;
  std::deque<Packet> air;
  FakeRadio radio("solo", &air);
  FakeClock clock;
  MissionState before;
  {
    auto wal = WalStorage::Open(fs, tmpl);
    ASSERT_TRUE(wal.ok());
    auto d = NodeDriver::Open(Cfg("solo", {"solo"}), **wal, radio, clock, nullptr);
    ASSERT_TRUE(d.ok());
    for (int i = 0; i < 30 && !(*d)->is_leader(); ++i) ASSERT_TRUE((*d)->Tick().ok());
    ASSERT_TRUE((*d)->is_leader());
    ASSERT_TRUE((*d)->Propose(StartSearch{}).ok());
    for (std::uint64_t s = 1; s <= 9; ++s) {
      ASSERT_TRUE((*d)->Propose(ReportSighting{"solo", s, 7.0 * static_cast<double>(s), 1, 0.9}).ok());
    }
    before = (*d)->mission();
    EXPECT_EQ(before.candidates().size(), 9u);  // 7 m apart: nine places, none confirmed by one view
  }
  {
    auto wal = WalStorage::Open(fs, tmpl);
    ASSERT_TRUE(wal.ok());
    EXPECT_GT((*wal)->Load()->snapshot.index, 0u);
    auto d = NodeDriver::Open(Cfg("solo", {"solo"}), **wal, radio, clock, nullptr);
    ASSERT_TRUE(d.ok()) << d.error().ToString();
    EXPECT_EQ((*d)->mission(), before);
  }
  std::filesystem::remove_all(tmpl);
}

// The entry log on real files: after a restart the tap yields every entry again, in index
// order, from the snapshot and the WAL; storage of another machine's snapshot does not open.
TEST(NodeDriver, EntryLogReplaysTheWalToTheTapAfterARestart) {
  std::string tmpl = (std::filesystem::temp_directory_path() / "swarmbox-drv-XXXXXX").string();
  ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
  PosixFileSystem fs;
  std::deque<Packet> air;
  FakeRadio radio("solo", &air);
  FakeClock clock;
  std::vector<Committed> before;
  {
    auto wal = WalStorage::Open(fs, tmpl);
    ASSERT_TRUE(wal.ok());
    auto d = NodeDriver::Open(Cfg("solo", {"solo"}), **wal, radio, clock, nullptr,
                              std::make_unique<EntryLogMachine>());
    ASSERT_TRUE(d.ok());
    for (int i = 0; i < 30 && !(*d)->is_leader(); ++i) ASSERT_TRUE((*d)->Tick().ok());
    ASSERT_TRUE((*d)->is_leader());
    EXPECT_EQ((*d)->leader(), "solo");
    for (int k = 0; k < 11; ++k) {
      const std::string text = "entry " + std::to_string(k);
      ASSERT_TRUE((*d)->Propose(Bytes(text.begin(), text.end())).ok());
    }
    (*d)->TakeCommitted(&before);
    ASSERT_EQ(before.size(), 11u);
    for (std::size_t k = 1; k < before.size(); ++k) EXPECT_LT(before[k - 1].index, before[k].index);
  }
  {
    auto wal = WalStorage::Open(fs, tmpl);
    ASSERT_TRUE(wal.ok());
    EXPECT_GT((*wal)->Load()->snapshot.index, 0u);  // part comes from the snapshot
    auto d = NodeDriver::Open(Cfg("solo", {"solo"}), **wal, radio, clock, nullptr,
                              std::make_unique<EntryLogMachine>());
    ASSERT_TRUE(d.ok()) << d.error().ToString();
    std::vector<Committed> replay;
    (*d)->TakeCommitted(&replay);
    EXPECT_EQ(replay, before);
  }
  {
    auto wal = WalStorage::Open(fs, tmpl);
    ASSERT_TRUE(wal.ok());
    auto d = NodeDriver::Open(Cfg("solo", {"solo"}), **wal, radio, clock, nullptr);  // mission
    ASSERT_FALSE(d.ok());
    EXPECT_NE(d.error().ToString().find("restoring the state machine from the stored snapshot"),
              std::string::npos)
        << d.error().ToString();
  }
  std::filesystem::remove_all(tmpl);
}

}  // namespace
}  // namespace swarmbox::raft
