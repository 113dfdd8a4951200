// The replicated mission state machine: phases, confirmation rule, determinism, snapshots.
#include "swarmbox/raft/mission_state.hpp"

#include <gtest/gtest.h>

#include <random>

namespace swarmbox::raft {
namespace {

class MissionStateTest : public ::testing::Test {
 protected:
  ApplyResult Do(const MissionCommand& c) { return m_.Apply(++index_, c); }
  MissionState m_;
  std::uint64_t index_ = 0;
};

TEST_F(MissionStateTest, FullMissionWalksThroughEveryPhase) {
  ApplyResult r = Do(StartSearch{});
  ASSERT_TRUE(r.accepted);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, MissionEvent::Kind::kPhase);
  EXPECT_EQ(r.events[0].phase, MissionPhase::kSearch);
  EXPECT_EQ(r.events[0].index, 1u);
  ASSERT_TRUE(Do(AssignSectors{{Sector{"scout_1", 0, 0, 50, 100}, Sector{"scout_2", 50, 0, 100, 100}}})
                  .accepted);
  ASSERT_NE(m_.SectorOf("scout_2"), nullptr);
  EXPECT_EQ(m_.SectorOf("scout_2")->x_min_m, 50);
  r = Do(ReportSighting{"scout_1", 1, 40, 60, 0.95});
  ASSERT_TRUE(r.accepted);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, MissionEvent::Kind::kVictimConfirmed);
  EXPECT_EQ(r.events[0].victim.id, 1u);
  ASSERT_TRUE(Do(ConvergeOn{1}).accepted);
  EXPECT_EQ(m_.phase(), MissionPhase::kConverge);
  ASSERT_TRUE(Do(BeginRescue{1, "lifter"}).accepted);
  EXPECT_EQ(m_.phase(), MissionPhase::kRescue);
  EXPECT_EQ(m_.FindVictim(1)->status, VictimStatus::kBeingRescued);
  EXPECT_EQ(m_.FindVictim(1)->rescuer, "lifter");
  ASSERT_TRUE(Do(MarkRescued{1}).accepted);
  EXPECT_EQ(m_.FindVictim(1)->status, VictimStatus::kRescued);
  EXPECT_EQ(m_.phase(), MissionPhase::kSearch);
  ASSERT_TRUE(Do(ReturnHome{}).accepted);
  ASSERT_TRUE(Do(CompleteMission{}).accepted);
  EXPECT_EQ(m_.phase(), MissionPhase::kComplete);
  EXPECT_EQ(m_.applied_index(), 8u);
}

TEST_F(MissionStateTest, InvalidTransitionsAreRejectedWithReason) {
  ApplyResult r = Do(ConvergeOn{1});
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, "cannot converge in phase IDLE");
  Do(StartSearch{});
  r = Do(ConvergeOn{3});
  EXPECT_EQ(r.reason, "no victim 3");
  r = Do(CompleteMission{});
  EXPECT_EQ(r.reason, "cannot complete in phase SEARCH");
  r = Do(AssignSectors{{Sector{"scout_1", 10, 0, 5, 100}}});
  EXPECT_EQ(r.reason, "sector of scout_1 is not a rectangle with min < max");
  EXPECT_TRUE(m_.sectors().empty());
  EXPECT_EQ(m_.phase(), MissionPhase::kSearch);
}

TEST_F(MissionStateTest, TwoIndependentSightingsConfirmAtTheirMean) {
  Do(StartSearch{});
  ApplyResult r = Do(ReportSighting{"scout_1", 1, 10, 20, 0.6});
  EXPECT_TRUE(r.events.empty());
  // The same drone again does not confirm its own sighting.
  r = Do(ReportSighting{"scout_1", 2, 11, 20, 0.6});
  EXPECT_TRUE(r.events.empty());
  // Another drone more than 5 m away does not either.
  r = Do(ReportSighting{"scout_2", 1, 30, 20, 0.6});
  EXPECT_TRUE(r.events.empty());
  r = Do(ReportSighting{"scout_2", 2, 14, 20, 0.7});
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, MissionEvent::Kind::kVictimConfirmed);
  // Nearest pending from another drone: (11, 20) -> mean (12.5, 20).
  EXPECT_DOUBLE_EQ(r.events[0].victim.x_m, 12.5);
  EXPECT_DOUBLE_EQ(r.events[0].victim.y_m, 20);
  EXPECT_EQ(r.events[0].victim.confirmed_by, (std::vector<std::string>{"scout_1", "scout_2"}));
  // A third sighting nearby is the same victim.
  r = Do(ReportSighting{"scout_3", 1, 13, 21, 0.99});
  EXPECT_TRUE(r.events.empty());
  EXPECT_EQ(m_.victims().size(), 1u);
  EXPECT_EQ(m_.victims()[0].confirmed_by.size(), 3u);
}

TEST_F(MissionStateTest, LowConfidenceAndDuplicateSightingsAreRejected) {
  Do(StartSearch{});
  EXPECT_EQ(Do(ReportSighting{"scout_1", 1, 0, 0, 0.3}).reason, "sighting confidence below 0.5");
  EXPECT_TRUE(Do(ReportSighting{"scout_1", 1, 0, 0, 0.6}).accepted);
  // A retried proposal that commits twice is applied once.
  EXPECT_EQ(Do(ReportSighting{"scout_1", 1, 0, 0, 0.6}).reason,
            "duplicate or out-of-order sighting seq 1 from scout_1");
  EXPECT_EQ(Do(ReportSighting{"scout_1", 2, 0, 0, 1.5}).reason,
            "sighting with a non-finite position or a confidence outside [0, 1]");
}

TEST_F(MissionStateTest, SnapshotRoundTripsEveryField) {
  Do(StartSearch{});
  Do(AssignSectors{{Sector{"a", 0, 0, 1, 1}}});
  Do(ReportSighting{"a", 1, 5, 5, 0.6});
  Do(ReportSighting{"b", 4, 100, 5, 0.95});
  Do(ConvergeOn{1});
  Do(BeginRescue{1, "lifter"});
  auto back = MissionState::DecodeSnapshot(m_.EncodeSnapshot());
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(*back, m_);
  // The restored state goes on exactly like the original.
  MissionState copy = *back;
  EXPECT_EQ(copy.Apply(7, MarkRescued{1}).accepted, m_.Apply(7, MarkRescued{1}).accepted);
  EXPECT_EQ(copy, m_);
}

TEST_F(MissionStateTest, CorruptSnapshotIsAnErrorNotACrash) {
  Do(StartSearch{});
  Do(ReportSighting{"a", 1, 5, 5, 0.95});
  const Bytes good = m_.EncodeSnapshot();
  std::mt19937_64 rng(7);
  for (int i = 0; i < 20000; ++i) {
    Bytes b = good;
    b[rng() % b.size()] = static_cast<std::uint8_t>(rng());
    if (i % 2) b.resize(rng() % b.size());
    (void)MissionState::DecodeSnapshot(b);  // must not crash or read out of bounds
  }
  Bytes bad = good;
  bad[0] = 9;
  auto r = MissionState::DecodeSnapshot(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message(), "unsupported snapshot version 9");
}

TEST_F(MissionStateTest, UndecodableCommandIsRejectedDeterministically) {
  const Bytes junk{1, 200, 3};
  ApplyResult r = m_.ApplyEncoded(1, junk);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, "undecodable command: unknown command kind 200");
  EXPECT_EQ(m_.applied_index(), 1u);
}

TEST(MissionCommand, EveryCommandRoundTrips) {
  const std::vector<MissionCommand> all = {
      StartSearch{}, AssignSectors{{Sector{"x", -1, -2, 3, 4}}},
      ReportSighting{"s", 9, 1.25, -3.5, 0.75}, ConfirmVictim{"ground", 7, 8}, ConvergeOn{3},
      BeginRescue{3, "lifter"}, MarkRescued{3}, ReturnHome{}, CompleteMission{}};
  for (const MissionCommand& c : all) {
    auto back = DecodeCommand(EncodeCommand(c));
    ASSERT_TRUE(back.ok()) << CommandName(c) << ": " << back.error().ToString();
    EXPECT_EQ(*back, c) << CommandName(c);
  }
}

// Two replicas applying the same random command sequence end in the same state (determinism).
TEST(MissionCommand, SameLogSameStateOnEveryReplica) {
  std::mt19937_64 rng(99);
  MissionState a, b;
  for (std::uint64_t i = 1; i <= 2000; ++i) {
    MissionCommand c;
    switch (rng() % 6) {
      case 0: c = StartSearch{}; break;
      case 1: c = ConvergeOn{static_cast<std::uint32_t>(1 + rng() % 4)}; break;
      case 2: c = BeginRescue{static_cast<std::uint32_t>(1 + rng() % 4), "lifter"}; break;
      case 3: c = MarkRescued{static_cast<std::uint32_t>(1 + rng() % 4)}; break;
      default:
        c = ReportSighting{"d" + std::to_string(rng() % 3), i, static_cast<double>(rng() % 50),
                           static_cast<double>(rng() % 50), static_cast<double>(rng() % 100) / 100};
    }
    const Bytes enc = EncodeCommand(c);
    a.ApplyEncoded(i, enc);
    b.Apply(i, *DecodeCommand(enc));
  }
  EXPECT_EQ(a, b);
  EXPECT_FALSE(a.victims().empty());
}

}  // namespace
}  // namespace swarmbox::raft
