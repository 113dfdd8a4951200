// The passive RaftService without DDS or wall clock (unit): services in one thread on a
// ManualClock, wired through SimRadio (sim_radio.hpp). The tick grid and its cap after a clock
// jump, and a paused follower rejoining; the loud stop when storage fails; junk survived; a
// restart re-applying the log (the mission's, and the entry log's replay to the tap); three nodes electing and committing, byte for byte the same event
// lines for the same inputs; and the failover time after a leader stops, with the trial's
// timings over a 100 +- 20 ms / 5% link.
#include "swarmbox/raft_service/raft_service.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "sim_radio.hpp"
#include "support/files.hpp"
#include "support/flaky_file_system.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::raft_service {
namespace {

using testing::ManualClock;
using testing::SimLink;
using testing::SimRadio;
using swarmbox::testing::FlakyFileSystem;

constexpr std::int64_t kStepUs = 4000;  // the lockstep's 4 ms

// A fresh directory under /tmp, removed with everything in it at the end.
struct TempDir {
  explicit TempDir(const std::string& prefix) : path(swarmbox::testing::MakeTempDir(prefix)) {}
  ~TempDir() {
    if (!path.empty()) std::filesystem::remove_all(path);
  }
  std::string path;
};

bool Contains(const std::vector<std::string>& lines, const std::string& part) {
  return std::any_of(lines.begin(), lines.end(),
                     [&](const std::string& l) { return l.find(part) != std::string::npos; });
}
std::string Joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const std::string& l : lines) s += l + "\n";
  return s;
}

// A transport for a cluster of one: nothing is ever sent.
class NoRadio final : public raft::Transport {
 public:
  void Send(const std::string&, std::span<const std::uint8_t>) override { ++sent; }
  int sent = 0;
};

RaftServiceConfig SoloConfig(const std::string& dir) {
  RaftServiceConfig c;
  c.driver.self = "solo";
  c.driver.members = {"solo"};
  c.driver.seed = 3;
  c.data_dir = dir;
  return c;
}

// Steps `clock` by 4 ms and ticks `s` until `done` or `max_s` of clock time.
bool StepUntil(ManualClock& clock, RaftService& s, const std::function<bool()>& done, double max_s) {
  const std::int64_t end = clock.now_us() + static_cast<std::int64_t>(max_s * 1e6);
  while (clock.now_us() < end) {
    clock.Advance(kStepUs);
    (void)s.Tick();
    if (done()) return true;
  }
  return done();
}

// ---- the tick grid -------------------------------------------------------------------------

TEST(RaftServiceTicks, OneTickPerTickMsOfTheClockOnAFixedGrid) {
  const TempDir tmp("swarmbox_raft_ticks_");
  RaftServiceConfig cfg = SoloConfig(tmp.path);
  cfg.driver.tick_ms = 50;
  cfg.driver.heartbeat_ms = 200;
  cfg.driver.election_timeout_ms = 1500;
  ManualClock clock;
  clock.Set(2'000'000);  // the grid starts where the clock is at Start: 2.0 s
  NoRadio radio;
  std::vector<std::string> lines;
  auto s = RaftService::Start(cfg, radio, clock, [&](const std::string& l) { lines.push_back(l); });
  ASSERT_TRUE(s) << s.error().ToString();
  EXPECT_EQ((*s)->max_catch_up_ticks(), 4);  // heartbeat_ms / tick_ms
  // Given 4 ms steps (t_k = 2.0 + k * 0.004, whose doubles are not exact), when ticked every
  // step for 1 s, then exactly one tick per 50 ms, the 20th at exactly 3.0 s.
  for (int k = 1; k <= 250; ++k) {
    clock.Set(2'000'000 + k * kStepUs);
    ASSERT_TRUE((*s)->Tick());
    ASSERT_EQ((*s)->ticks(), static_cast<std::uint64_t>(k * kStepUs / 50'000)) << "step " << k;
  }
  EXPECT_DOUBLE_EQ((*s)->next_tick_s(), 3.05);
  // Calling again at the same time runs nothing.
  ASSERT_TRUE((*s)->Tick());
  EXPECT_EQ((*s)->ticks(), 20u);
  // A loop late by 150 ms (3 ticks, within the cap) runs all three.
  clock.Set(3'150'000);
  ASSERT_TRUE((*s)->Tick());
  EXPECT_EQ((*s)->ticks(), 23u);
  EXPECT_EQ((*s)->dropped_ticks(), 0u);
  // A 10 s pause (200 ticks owed) runs the cap and drops the rest; the grid is kept.
  clock.Set(13'170'000);
  ASSERT_TRUE((*s)->Tick());
  EXPECT_EQ((*s)->ticks(), 27u);
  EXPECT_EQ((*s)->dropped_ticks(), 196u);
  EXPECT_DOUBLE_EQ((*s)->next_tick_s(), 13.2);
  EXPECT_EQ(radio.sent, 0);
}

TEST(RaftServiceTicks, ASoloNodeLeadsAfterItsElectionTimeoutOfClockTime) {
  const TempDir tmp("swarmbox_raft_solo_");
  ManualClock clock;
  std::vector<std::string> lines;
  NoRadio radio;
  auto s = RaftService::Start(SoloConfig(tmp.path), radio, clock,
                              [&](const std::string& l) { lines.push_back(l); });
  ASSERT_TRUE(s) << s.error().ToString();
  // Without Tick() time does not pass for Raft, however long the wall clock waits.
  EXPECT_FALSE((*s)->is_leader());
  // Default timings: election timeout 500 ms randomised to [500, 1000) ms.
  ASSERT_TRUE(StepUntil(clock, **s, [&] { return (*s)->is_leader(); }, 5.0)) << Joined(lines);
  EXPECT_GE(clock.NowS(), 0.5);
  EXPECT_LT(clock.NowS(), 1.0 + 0.05);
  // The event carries the clock of the step that made it.
  EXPECT_TRUE(Contains(lines, LogEvent(clock.NowS(), "solo", "leader_elected").str() + " term="))
      << Joined(lines);
  EXPECT_EQ((*s)->leader(), "solo");
  EXPECT_EQ((*s)->self(), "solo");
}

// ---- failures ------------------------------------------------------------------------------

TEST(RaftServiceSim, StorageFailureStopsTheNodeLoudly) {
  FlakyFileSystem fs;
  const TempDir tmp("swarmbox_raft_flaky_");
  RaftServiceConfig cfg = SoloConfig(tmp.path);
  cfg.file_system = &fs;
  ManualClock clock;
  NoRadio radio;
  std::vector<std::string> lines;
  auto s = RaftService::Start(cfg, radio, clock, [&](const std::string& l) { lines.push_back(l); });
  ASSERT_TRUE(s) << s.error().ToString();
  ASSERT_TRUE(StepUntil(clock, **s, [&] { return (*s)->is_leader(); }, 5.0)) << Joined(lines);
  EXPECT_FALSE((*s)->stopped());
  fs.fail_sync = true;
  // The WAL's fsync fails on this proposal's Ready (or the next tick's).
  (void)(*s)->Propose(raft::StartSearch{});
  ASSERT_TRUE(StepUntil(clock, **s, [&] { return (*s)->stopped(); }, 1.0)) << Joined(lines);
  ASSERT_FALSE((*s)->health());
  EXPECT_NE((*s)->health().error().ToString().find("injected"), std::string::npos);
  EXPECT_TRUE(Contains(lines, "event=raft_stopped")) << Joined(lines);
  auto again = (*s)->Propose(raft::StartSearch{});
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().ToString().find("injected"), std::string::npos);
  auto tick = (*s)->Tick();
  ASSERT_FALSE(tick);
  EXPECT_NE(tick.error().ToString().find("injected"), std::string::npos);
}

TEST(RaftServiceSim, UndecodablePayloadsAreCountedNotFatal) {
  const TempDir tmp("swarmbox_raft_junk_");
  ManualClock clock;
  NoRadio radio;
  std::vector<std::string> lines;
  auto s = RaftService::Start(SoloConfig(tmp.path), radio, clock,
                              [&](const std::string& l) { lines.push_back(l); });
  ASSERT_TRUE(s) << s.error().ToString();
  ASSERT_TRUE(StepUntil(clock, **s, [&] { return (*s)->is_leader(); }, 5.0)) << Joined(lines);
  // Another cluster's node, or a damaged datagram, talks to us.
  const std::vector<std::uint8_t> junk = {1, 0xde, 0xad, 0xbe, 0xef, 11, 1, 1, 1};
  (*s)->OnPayload(junk);
  (*s)->OnPayload(std::vector<std::uint8_t>{});
  EXPECT_EQ((*s)->protocol_errors(), 2u);
  EXPECT_TRUE((*s)->health().ok());
  EXPECT_TRUE((*s)->is_leader());
  EXPECT_TRUE((*s)->Propose(raft::StartSearch{}));
  EXPECT_TRUE(StepUntil(clock, **s,
                        [&] { return (*s)->mission().phase() == raft::MissionPhase::kSearch; }, 1.0));
}

TEST(RaftServiceSim, RestartReappliesTheDurableLog) {
  const TempDir tmp("swarmbox_raft_restart_");
  const RaftServiceConfig cfg = SoloConfig(tmp.path);
  ManualClock clock;
  NoRadio radio;
  raft::MissionState before;
  {
    std::vector<std::string> lines;
    auto s = RaftService::Start(cfg, radio, clock, [&](const std::string& l) { lines.push_back(l); });
    ASSERT_TRUE(s) << s.error().ToString();
    ASSERT_TRUE(StepUntil(clock, **s, [&] { return (*s)->is_leader(); }, 5.0));
    ASSERT_TRUE((*s)->Propose(raft::StartSearch{}));
    ASSERT_TRUE((*s)->Propose(raft::ConfirmVictim{"op", 10.0, 20.0}));
    ASSERT_TRUE(StepUntil(clock, **s, [&] { return (*s)->mission().victims().size() == 1; }, 1.0));
    before = (*s)->mission();
  }
  std::vector<std::string> lines;
  auto s = RaftService::Start(cfg, radio, clock, [&](const std::string& l) { lines.push_back(l); });
  ASSERT_TRUE(s) << s.error().ToString();
  ASSERT_TRUE(StepUntil(clock, **s, [&] {
    return (*s)->mission().applied_index() >= before.applied_index();
  }, 5.0)) << Joined(lines);
  EXPECT_EQ((*s)->mission().victims(), before.victims());
  EXPECT_EQ((*s)->mission().phase(), raft::MissionPhase::kSearch);
  EXPECT_TRUE(Contains(lines, "event=victim_confirmed id=1")) << Joined(lines);
}

// Any state machine through the service: a brain's bytes in the entry log, and after a restart
// on the same WAL the tap replays every one of them, in index order, before anything new.
TEST(RaftServiceSim, EntryLogTapReplaysTheWholeLogAfterARestart) {
  const TempDir tmp("swarmbox_raft_entry_log_");
  RaftServiceConfig cfg = SoloConfig(tmp.path);
  cfg.driver.snapshot_every_entries = 5;  // part of the log lives in a snapshot
  ManualClock clock;
  NoRadio radio;
  std::vector<raft::Committed> before;
  auto text = [](int k) {
    const std::string t = "pos solo " + std::to_string(k) + ".000 0.000";
    return raft::Bytes(t.begin(), t.end());
  };
  {
    auto s = RaftService::Start(cfg, radio, clock, nullptr, std::make_unique<raft::EntryLogMachine>());
    ASSERT_TRUE(s) << s.error().ToString();
    ASSERT_TRUE(StepUntil(clock, **s, [&] { return (*s)->is_leader(); }, 5.0));
    EXPECT_EQ((*s)->leader(), "solo");
    EXPECT_EQ((*s)->FindMission(), nullptr);
    for (int k = 1; k <= 12; ++k) ASSERT_TRUE((*s)->ProposeBytes(text(k)));
    (*s)->TakeCommitted(&before);
  }
  ASSERT_EQ(before.size(), 12u);
  for (int k = 1; k <= 12; ++k) EXPECT_EQ(before[static_cast<std::size_t>(k - 1)].data, text(k));
  std::vector<std::string> lines;
  auto s = RaftService::Start(cfg, radio, clock, [&](const std::string& l) { lines.push_back(l); },
                              std::make_unique<raft::EntryLogMachine>());
  ASSERT_TRUE(s) << s.error().ToString();
  std::vector<raft::Committed> replay;
  (*s)->TakeCommitted(&replay);
  EXPECT_EQ(replay, before);
  ASSERT_TRUE(StepUntil(clock, **s, [&] { return (*s)->is_leader(); }, 5.0));
  ASSERT_TRUE((*s)->ProposeBytes(text(13)));
  (*s)->TakeCommitted(&replay);
  ASSERT_EQ(replay.size(), 1u);
  EXPECT_EQ(replay[0].data, text(13));
  EXPECT_GT(replay[0].index, before.back().index);
  EXPECT_FALSE(Contains(lines, "event=mission_state")) << Joined(lines);
}

// ---- clusters on the simulated radio -------------------------------------------------------

// N passive services on one ManualClock and SimRadio, stepped as the agents' control loops are:
// every 4 ms, node by node in order, the deliveries due (in delivery order), then Tick().
class SimCluster {
 public:
  SimCluster(const std::vector<std::string>& names, const raft::DriverConfig& timings, SimLink link,
             const std::string& dir)
      : names_(names), radio_(names, link, clock_), up_(names.size(), true) {
    for (std::size_t i = 0; i < names_.size(); ++i) {
      RaftServiceConfig c;
      c.driver = timings;
      c.driver.self = names_[i];
      c.driver.members = names_;
      c.data_dir = dir + "/" + names_[i];
      auto s = RaftService::Start(c, radio_.Endpoint(i), clock_,
                                  [this](const std::string& l) { lines_.push_back(l); });
      EXPECT_TRUE(s) << s.error().ToString();
      nodes_.push_back(s ? std::move(*s) : nullptr);
    }
  }

  bool ok() const {
    return std::all_of(nodes_.begin(), nodes_.end(), [](const auto& n) { return n != nullptr; });
  }
  void Step() {
    clock_.Advance(kStepUs);
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      if (!up_[i]) {
        radio_.DropPendingFor(i);
        continue;
      }
      batch_.clear();
      radio_.TakeDue(i, &batch_);
      for (const raft::Bytes& b : batch_) nodes_[i]->OnPayload(b);
      EXPECT_TRUE(nodes_[i]->Tick()) << names_[i];
    }
  }
  // Steps until `done` or until the clock reaches `until_s`.
  bool RunUntil(const std::function<bool()>& done, double until_s) {
    while (clock_.NowS() < until_s) {
      Step();
      if (done()) return true;
    }
    return done();
  }
  // The running node that leads, if any.
  std::optional<std::size_t> Leader() const {
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      if (up_[i] && nodes_[i]->is_leader()) return i;
    }
    return std::nullopt;
  }
  // Every running node applied the same mission with phase `p`.
  bool AllUpIn(raft::MissionPhase p) const {
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      if (up_[i] && nodes_[i]->mission().phase() != p) return false;
    }
    return true;
  }
  // Out of the loop: no ticks, and what is sent to it is lost (a stopped, paused or out drone).
  void Stop(std::size_t i) { up_[i] = false; }
  void Resume(std::size_t i) { up_[i] = true; }

  RaftService& node(std::size_t i) { return *nodes_[i]; }
  bool up(std::size_t i) const { return up_[i]; }
  std::size_t size() const { return nodes_.size(); }
  const std::string& name(std::size_t i) const { return names_[i]; }
  const ManualClock& clock() const { return clock_; }
  const std::vector<std::string>& lines() const { return lines_; }
  const SimRadio& radio() const { return radio_; }

 private:
  std::vector<std::string> names_;
  ManualClock clock_;
  SimRadio radio_;
  std::vector<bool> up_;
  std::vector<std::string> lines_;  // every node's events, in the order they were printed
  std::vector<std::unique_ptr<RaftService>> nodes_;  // last: destroyed first
  std::vector<raft::Bytes> batch_;
};

const std::vector<std::string> kTrio = {"scout_1", "scout_2", "lifter"};

// The trial defaults (trials/*.yaml raft: tick 50, heartbeat 200, election timeout 1500 ms).
raft::DriverConfig TrialTimings(std::uint64_t seed) {
  raft::DriverConfig d;
  d.tick_ms = 50;
  d.heartbeat_ms = 200;
  d.election_timeout_ms = 1500;
  d.seed = seed;
  return d;
}

// The mesh impairment of the failover figure: 100 +- 20 ms, 5% loss.
SimLink FailoverLink(std::uint64_t seed) {
  return SimLink{.delay_ms = 100, .jitter_ms = 20, .loss = 0.05, .seed = seed};
}

// Elect, commit SEARCH on all three, then RETURN; the event lines of the whole run.
std::vector<std::string> ElectAndCommit(std::uint64_t seed, const std::string& dir) {
  SimCluster c(kTrio, TrialTimings(seed), FailoverLink(seed), dir);
  EXPECT_TRUE(c.ok());
  if (!c.ok()) return {};
  EXPECT_TRUE(c.RunUntil([&] { return c.Leader().has_value(); }, 20.0)) << Joined(c.lines());
  const std::size_t l = *c.Leader();
  EXPECT_TRUE(c.RunUntil([&] { return c.node(l).Propose(raft::StartSearch{}).ok(); }, 25.0));
  EXPECT_TRUE(c.RunUntil([&] { return c.AllUpIn(raft::MissionPhase::kSearch); }, 30.0))
      << Joined(c.lines());
  for (std::size_t i = 0; i < c.size(); ++i) {
    EXPECT_EQ(c.node(i).mission(), c.node(l).mission()) << c.name(i);
    EXPECT_EQ(c.node(i).leader(), c.name(l)) << c.name(i);
  }
  EXPECT_TRUE(c.node(l).Propose(raft::ReturnHome{}));
  EXPECT_TRUE(c.RunUntil([&] { return c.AllUpIn(raft::MissionPhase::kReturn); }, 35.0))
      << Joined(c.lines());
  // Run on a little: heartbeats and their answers belong to the compared output too.
  c.RunUntil([] { return false; }, c.clock().NowS() + 2.0);
  return c.lines();
}

TEST(RaftServiceSim, ThreeNodesElectAndCommitTheSameWayEveryTime) {
  const TempDir tmp("swarmbox_raft_sim_");
  const std::vector<std::string> first = ElectAndCommit(7, tmp.path + "/a");
  const std::vector<std::string> second = ElectAndCommit(7, tmp.path + "/b");
  ASSERT_FALSE(first.empty());
  EXPECT_TRUE(Contains(first, "event=leader_elected")) << Joined(first);
  EXPECT_TRUE(Contains(first, "event=mission_state state=SEARCH")) << Joined(first);
  EXPECT_TRUE(Contains(first, "event=mission_state state=RETURN")) << Joined(first);
  // Same seed, same inputs: the same event lines, byte for byte, in the same order.
  EXPECT_EQ(Joined(first), Joined(second));
  // Another seed (election timeouts and the link's draws) gives another run.
  const std::vector<std::string> other = ElectAndCommit(8, tmp.path + "/c");
  EXPECT_NE(Joined(first), Joined(other));
}

// A follower paused for 10 s (docker pause, or out of the lockstep) comes back with its clock
// 10 s later: Tick() runs the capped catch-up and drops the rest, the node rejoins on the
// leader's next heartbeat and catches up, and nobody's term moves (no election, Raft §5.2; PreVote
// and CheckQuorum would also refuse one while the leader is healthy).
TEST(RaftServiceSim, APausedFollowerRejoinsWithoutAnElection) {
  const TempDir tmp("swarmbox_raft_pause_");
  SimCluster c(kTrio, TrialTimings(5), FailoverLink(5), tmp.path);
  ASSERT_TRUE(c.ok());
  ASSERT_TRUE(c.RunUntil([&] { return c.Leader().has_value(); }, 20.0)) << Joined(c.lines());
  const std::size_t l = *c.Leader();
  ASSERT_TRUE(c.RunUntil([&] { return c.node(l).Propose(raft::StartSearch{}).ok(); }, 25.0));
  ASSERT_TRUE(c.RunUntil([&] { return c.AllUpIn(raft::MissionPhase::kSearch); }, 30.0));
  const std::size_t f = (l + 1) % c.size();
  const std::uint64_t term = c.node(l).term();
  const std::uint64_t ticks_before = c.node(f).ticks();
  const double paused_at = c.clock().NowS();
  c.Stop(f);
  // The others go on and commit without it (two of three are a quorum).
  ASSERT_TRUE(c.node(l).Propose(raft::ReturnHome{}));
  c.RunUntil([] { return false; }, paused_at + 10.0);
  ASSERT_EQ(c.node(l).mission().phase(), raft::MissionPhase::kReturn);
  c.Resume(f);
  ASSERT_TRUE(c.RunUntil([&] { return c.node(f).mission().phase() == raft::MissionPhase::kReturn; },
                         paused_at + 15.0))
      << Joined(c.lines());
  c.RunUntil([] { return false; }, paused_at + 20.0);
  // 10 s owed 200 ticks: 4 ran at once (heartbeat_ms / tick_ms), 196 were dropped.
  EXPECT_EQ(c.node(f).dropped_ticks(), 196u);
  EXPECT_EQ(c.node(f).ticks() - ticks_before, 400u - 196u);
  for (std::size_t i = 0; i < c.size(); ++i) {
    EXPECT_EQ(c.node(i).term(), term) << c.name(i) << "\n" << Joined(c.lines());
    EXPECT_EQ(c.node(i).leader(), c.name(l)) << c.name(i);
    EXPECT_EQ(c.node(i).mission(), c.node(l).mission()) << c.name(i);
  }
}

struct Failover {
  double failover_ms = 0;
  std::string old_leader, new_leader;
  std::uint64_t term = 0;
};

// Elect and commit, stop the leader at exactly `stop_at_s`, and measure the time to the first
// event=leader_elected naming another node (Raft §5.2), then check the survivors still commit.
std::optional<Failover> MeasureFailover(std::uint64_t seed, double stop_at_s, const std::string& dir) {
  SimCluster c(kTrio, TrialTimings(seed), FailoverLink(seed), dir);
  if (!c.ok()) return std::nullopt;
  EXPECT_TRUE(c.RunUntil([&] { return c.Leader().has_value(); }, stop_at_s));
  if (!c.Leader()) return std::nullopt;
  EXPECT_TRUE(c.RunUntil([&] { return c.node(*c.Leader()).Propose(raft::StartSearch{}).ok(); }, stop_at_s));
  EXPECT_TRUE(c.RunUntil([&] { return c.AllUpIn(raft::MissionPhase::kSearch); }, stop_at_s));
  c.RunUntil([] { return false; }, stop_at_s);
  const auto old = c.Leader();
  EXPECT_TRUE(old.has_value()) << "seed " << seed << ": no leader at the stop\n" << Joined(c.lines());
  if (!old) return std::nullopt;
  Failover f;
  f.old_leader = c.name(*old);
  const std::uint64_t old_term = c.node(*old).term();
  c.Stop(*old);
  const std::size_t seen = c.lines().size();
  const bool elected = c.RunUntil([&] {
    for (std::size_t i = seen; i < c.lines().size(); ++i) {
      const LogfmtFields fl = ParseLogfmt(c.lines()[i]);
      if (FindField(fl, "event") != "leader_elected") continue;
      const auto leader = FindField(fl, "leader");
      if (!leader || *leader == f.old_leader) continue;
      f.new_leader = *leader;
      f.term = std::stoull(FindField(fl, "term").value_or("0"));
      return true;
    }
    return false;
  }, stop_at_s + 30.0);
  EXPECT_TRUE(elected) << "seed " << seed << ": no new leader in 30 s\n" << Joined(c.lines());
  if (!elected) return std::nullopt;
  f.failover_ms = (c.clock().NowS() - stop_at_s) * 1000.0;
  EXPECT_GT(f.term, old_term);
  // The two survivors are a quorum of three: they go on committing.
  const double t_elected = c.clock().NowS();
  EXPECT_TRUE(c.RunUntil([&] {
    const auto l = c.Leader();
    return l && c.node(*l).Propose(raft::ReturnHome{}).ok();
  }, t_elected + 10.0));
  EXPECT_TRUE(c.RunUntil([&] { return c.AllUpIn(raft::MissionPhase::kReturn); }, t_elected + 20.0))
      << "seed " << seed << "\n" << Joined(c.lines());
  return f;
}

double Percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const double rank = p * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(rank);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (v[hi] - v[lo]) * (rank - static_cast<double>(lo));
}

TEST(RaftServiceSim, FailoverAfterTheLeaderStopsWithTheTrialTimingsOnALossyLink) {
  const TempDir tmp("swarmbox_raft_failover_");
  constexpr double kStopAtS = 10.0;
  constexpr int kRuns = 20;
  std::vector<double> ms;
  for (int r = 0; r < kRuns; ++r) {
    const std::uint64_t seed = 100 + static_cast<std::uint64_t>(r);
    const auto f = MeasureFailover(seed, kStopAtS, tmp.path + "/" + std::to_string(seed));
    ASSERT_TRUE(f.has_value()) << "seed " << seed;
    std::printf("%s\n", LogEvent(kStopAtS + f->failover_ms / 1000.0, "raft_sim", "raft_failover")
                            .Add("seed", seed)
                            .Add("old_leader", f->old_leader)
                            .Add("new_leader", f->new_leader)
                            .Add("term", f->term)
                            .Add("failover_ms", f->failover_ms, 0)
                            .str()
                            .c_str());
    // A follower only campaigns after a whole election timeout (>= 1500 ms of ticks) without
    // hearing from the leader, whose last heartbeat left at most one heartbeat (200 ms) before
    // the stop and arrived ~100 ms later; then a pre-vote and a vote round trip.
    EXPECT_GE(f->failover_ms, 1500.0 - 200.0) << "seed " << seed;
    // The longest randomised timeout (< 3000 ms) plus a few lost rounds.
    EXPECT_LE(f->failover_ms, 10'000.0) << "seed " << seed;
    ms.push_back(f->failover_ms);
  }
  const double mean = std::accumulate(ms.begin(), ms.end(), 0.0) / static_cast<double>(ms.size());
  std::printf("%s\n", LogEvent(kStopAtS, "raft_sim", "raft_failover_summary")
                          .Add("runs", kRuns)
                          .Add("tick_ms", 50)
                          .Add("heartbeat_ms", 200)
                          .Add("election_timeout_ms", 1500)
                          .Add("delay_ms", 100)
                          .Add("jitter_ms", 20)
                          .Add("loss", 0.05, 2)
                          .Add("stop_at_s", kStopAtS, 1)
                          .Add("failover_ms_min", *std::min_element(ms.begin(), ms.end()), 0)
                          .Add("failover_ms_p50", Percentile(ms, 0.5), 0)
                          .Add("failover_ms_p90", Percentile(ms, 0.9), 0)
                          .Add("failover_ms_max", *std::max_element(ms.begin(), ms.end()), 0)
                          .Add("failover_ms_mean", mean, 0)
                          .str()
                          .c_str());
  std::fflush(stdout);
}

}  // namespace
}  // namespace swarmbox::raft_service
