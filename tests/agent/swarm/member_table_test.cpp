// MemberTable (member_table.hpp) and the leader planner fed from it at 100 scouts: the table is
// kept per message, the planner hands all of them their sectors in one proposal.
#include "swarmbox/swarm/member_table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <variant>
#include <vector>

namespace swarmbox::swarm {
namespace {

using Vec2 = Eigen::Vector2d;

std::vector<std::string> Names(int scouts) {
  std::vector<std::string> out;
  for (int i = 1; i <= scouts; ++i) out.push_back("scout_" + std::to_string(i));
  out.push_back("lifter");
  return out;
}

TEST(MemberTable, KeepsTheNewestWordOfEachMemberAndIgnoresOthers) {
  const std::vector<std::string> members = Names(3);
  MemberTable t(members, "scout_1");
  EXPECT_EQ(t.heard(), 0u);
  EXPECT_TRUE(t.Update("scout_2", 1.0, Role::kScout, "taking_off", Vec2(4, 0)));
  EXPECT_TRUE(t.Update("scout_2", 2.0, Role::kScout, "searching", Vec2(50, 0)));
  EXPECT_FALSE(t.Update("scout_2", 1.5, Role::kScout, "on_ground", Vec2(4, 0)));   // older: reordered
  EXPECT_FALSE(t.Update("ground_station", 2.0, Role::kScout, "x", Vec2::Zero()));  // not a member
  EXPECT_FALSE(t.Update("scout_1", 2.0, Role::kScout, "x", Vec2::Zero()));         // this drone
  EXPECT_TRUE(t.IsPeer("lifter"));
  EXPECT_FALSE(t.IsPeer("scout_1"));
  EXPECT_FALSE(t.IsPeer("ground_station"));
  EXPECT_FALSE(t.lifter_heard());
  EXPECT_TRUE(t.Update("lifter", 2.0, Role::kLifter, "on_ground", Vec2(0, -10)));
  EXPECT_TRUE(t.lifter_heard());
  t.UpdateSelf(3.0, Role::kScout, "searching", Vec2(1, 2));
  EXPECT_EQ(t.heard(), 3u);
  const std::span<const RosterEntry> r = t.Roster(3.5);
  ASSERT_EQ(r.size(), 3u);
  const RosterEntry* s2 = t.Find("scout_2");
  ASSERT_NE(s2, nullptr);
  EXPECT_EQ(s2->mode, "searching");
  EXPECT_EQ(s2->position_m, Vec2(50, 0));
  EXPECT_DOUBLE_EQ(s2->age_s, 1.5);
  EXPECT_TRUE(std::isinf(s2->wall_age_s));  // no wall clock: the simulated age decides alone
  EXPECT_DOUBLE_EQ(t.Find("scout_1")->age_s, 0.0);
  EXPECT_EQ(t.Find("scout_3"), nullptr);  // never heard
  // netem: the wall age counts from when the word was received.
  EXPECT_TRUE(t.Update("scout_3", 3.0, Role::kScout, "searching", Vec2(9, 9), /*wall_s=*/100.0));
  t.Roster(3.5, 101.25);
  EXPECT_DOUBLE_EQ(t.Find("scout_3")->wall_age_s, 1.25);
}

// The leader's roster at 100 scouts comes from the table (fed by neighbours and status messages
// alike); the IDLE -> SEARCH step proposes ONE AssignSectors holding a sector for every scout,
// the cells tile the area, and each scout gets the cell whose place in the grid matches its own
// place on the 10 x 10 take-off grid.
TEST(LeaderPlannerAtScale, AssignsEveryOneOfAHundredScoutsInOneProposal) {
  const std::vector<std::string> members = Names(100);
  MemberTable table(members, "scout_1");
  const Rect area{-292, -292, 292, 292};  // a 600 m geofence, 8 m margin
  for (int i = 1; i <= 100; ++i) {
    const Vec2 home(4.0 * ((i - 1) % 10), 4.0 * ((i - 1) / 10));
    if (i == 1) {
      table.UpdateSelf(20.0, Role::kScout, "awaiting_sector", home);
    } else {
      table.Update("scout_" + std::to_string(i), 19.9, Role::kScout, "awaiting_sector", home);
    }
  }
  table.Update("lifter", 19.9, Role::kLifter, "on_ground", Vec2(0, -10));
  LeaderPlanner planner(LeaderConfig{.name = "scout_1", .search_area = area});
  raft::MissionState mission;
  MissionOutput out;
  planner.Step(20.0, mission, table.Roster(20.0), &out);
  ASSERT_EQ(out.proposals.size(), 2u);
  const auto* assign = std::get_if<raft::AssignSectors>(&out.proposals[0]);
  ASSERT_NE(assign, nullptr);
  ASSERT_EQ(assign->sectors.size(), 100u);
  EXPECT_TRUE(std::holds_alternative<raft::StartSearch>(out.proposals[1]));
  std::set<std::string> owners;
  double total = 0;
  for (const raft::Sector& s : assign->sectors) {
    owners.insert(s.drone);
    EXPECT_NEAR(s.x_max_m - s.x_min_m, 58.4, 1e-9) << s.drone;  // 10 x 10 square cells
    EXPECT_NEAR(s.y_max_m - s.y_min_m, 58.4, 1e-9) << s.drone;
    total += (s.x_max_m - s.x_min_m) * (s.y_max_m - s.y_min_m);
    // scout_i stands in column (i-1) % 10, row (i-1) / 10: its cell is in the same column and row.
    const int i = std::stoi(s.drone.substr(6)) - 1;
    EXPECT_EQ(static_cast<int>(std::floor((s.x_min_m + 292 + 1e-6) / 58.4)), i % 10) << s.drone;
    EXPECT_EQ(static_cast<int>(std::floor((s.y_min_m + 292 + 1e-6) / 58.4)), i / 10) << s.drone;
  }
  EXPECT_EQ(owners.size(), 100u);
  EXPECT_NEAR(total, 584.0 * 584.0, 1e-6);
  // Committed: the planner asks for nothing more while everyone searches (no per-scout proposals).
  mission.Apply(1, out.proposals[0]);
  mission.Apply(2, out.proposals[1]);
  for (int i = 1; i <= 100; ++i) {
    if (i == 1) {
      table.UpdateSelf(21.0, Role::kScout, "searching", Vec2::Zero());
    } else {
      table.Update("scout_" + std::to_string(i), 21.0, Role::kScout, "searching", Vec2::Zero());
    }
  }
  MissionOutput later;
  for (double t = 20.1; t < 25.0; t += 0.1) planner.Step(t, mission, table.Roster(t), &later);
  EXPECT_TRUE(later.proposals.empty());
}

}  // namespace
}  // namespace swarmbox::swarm
