// The stand-alone node's proposal script walks the mission state machine without getting stuck.
#include "swarmbox/raft_service/demo_mission.hpp"

#include <gtest/gtest.h>

#include <variant>

namespace swarmbox::raft_service {
namespace {

TEST(DemoMission, CyclesSearchConvergeRescueWithOneNewVictimPerRound) {
  raft::MissionState m;
  std::uint64_t index = 0;
  std::vector<raft::MissionPhase> phases;
  int victims_confirmed = 0;
  for (int step = 0; step < 13; ++step) {
    auto cmd = NextDemoCommand(m, "scout_1");
    ASSERT_TRUE(cmd.has_value());
    const raft::ApplyResult r = m.Apply(++index, *cmd);
    ASSERT_TRUE(r.accepted) << raft::CommandName(*cmd) << ": " << r.reason;
    for (const raft::MissionEvent& e : r.events) {
      if (e.kind == raft::MissionEvent::Kind::kPhase) phases.push_back(e.phase);
      if (e.kind == raft::MissionEvent::Kind::kVictimConfirmed) ++victims_confirmed;
    }
  }
  using P = raft::MissionPhase;
  const std::vector<P> want = {P::kSearch, P::kConverge, P::kRescue, P::kSearch,
                               P::kConverge, P::kRescue, P::kSearch, P::kConverge,
                               P::kRescue, P::kSearch};
  EXPECT_EQ(phases, want);
  EXPECT_EQ(victims_confirmed, 3);
  ASSERT_EQ(m.victims().size(), 3u);
  EXPECT_EQ(m.victims()[2].x_m, 3 * kDemoVictimSpacingM);
  EXPECT_EQ(m.victims()[0].rescuer, "scout_1");
}

TEST(DemoMission, RepeatedProposalBeforeCommitIsRejectedNotAppliedTwice) {
  raft::MissionState m;
  ASSERT_TRUE(m.Apply(1, raft::StartSearch{}).accepted);
  const auto cmd = NextDemoCommand(m, "a");
  ASSERT_TRUE(cmd.has_value());
  EXPECT_TRUE(m.Apply(2, *cmd).accepted);   // confirms victim 1 at (30, 0)
  EXPECT_FALSE(m.Apply(3, *cmd).accepted);  // the same proposal committed again
  EXPECT_EQ(m.victims().size(), 1u);
}

TEST(DemoMission, ReturnLeadsToCompleteAndThenNothing) {
  raft::MissionState m;
  ASSERT_TRUE(m.Apply(1, raft::StartSearch{}).accepted);
  ASSERT_TRUE(m.Apply(2, raft::ReturnHome{}).accepted);
  auto cmd = NextDemoCommand(m, "a");
  ASSERT_TRUE(cmd.has_value());
  EXPECT_TRUE(std::holds_alternative<raft::CompleteMission>(*cmd));
  ASSERT_TRUE(m.Apply(3, *cmd).accepted);
  EXPECT_FALSE(NextDemoCommand(m, "a").has_value());
}

}  // namespace
}  // namespace swarmbox::raft_service
