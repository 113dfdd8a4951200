// The scouts' safe height over rubble and trees (issue #23; ScoutConfig::min_clearance_m,
// MissionInput::obstacle_top_z_m): ScoutBehaviour step by step against a MissionState driven by
// hand, and a scout sweeping across a stand of trees on the kinematic rig (mission_sim.hpp) with
// and without the fake depth camera.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "mission_sim.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/swarm/scout_behaviour.hpp"

namespace swarmbox::swarm {
namespace {

using Eigen::Vector3d;

constexpr double kSearchAltitude_m = 30.0;  // ScoutConfig's default, home at z 0
constexpr double kMinClearance_m = 8.0;
const raft::Sector kSector{"scout_1", 0, 0, 60, 150};

int CountEvents(const MissionOutput& out, const std::string& name) {
  int n = 0;
  for (const LogEvent& e : out.events) n += e.str().find("event=" + name) != std::string::npos ? 1 : 0;
  return n;
}

// A scout searching its sector at the search altitude, and the committed state it reads.
class SafeHeight : public ::testing::Test {
 protected:
  void SetUpScout(double min_clearance_m) {
    ASSERT_TRUE(mission_.Apply(1, raft::AssignSectors{{kSector}}).accepted);
    ASSERT_TRUE(mission_.Apply(2, raft::StartSearch{}).accepted);
    scout_.emplace(
        ScoutConfig{.name = "scout_1", .home_m = Vector3d::Zero(), .min_clearance_m = min_clearance_m});
    Step(0.0, std::nullopt, {0, 0, 0.23});
    Step(1.0, std::nullopt, {0, 0, kSearchAltitude_m});
    Step(1.1, std::nullopt, {0, 0, kSearchAltitude_m});
    ASSERT_EQ(out_.mode, "searching");
  }
  // One tick at `t_s` with the depth camera's report `top_z_m` (nullopt: none).
  const MissionOutput& Step(double t_s, std::optional<double> top_z_m,
                            const Vector3d& p = {5, 5, kSearchAltitude_m}) {
    MissionInput in;
    in.t_s = t_s;
    in.mission = &mission_;
    in.position_m = p;
    in.obstacle_top_z_m = top_z_m;
    scout_->Step(in, &out_);
    return out_;
  }
  raft::MissionState mission_;
  std::optional<ScoutBehaviour> scout_;
  MissionOutput out_;
};

TEST_F(SafeHeight, ClimbsToTheObstaclesTopPlusTheClearanceAndLogsTheClimbOnce) {
  SetUpScout(kMinClearance_m);
  const double lane_z = scout_->lanes().front().position_m.z();
  ASSERT_DOUBLE_EQ(lane_z, kSearchAltitude_m);
  Step(2.0, 25.0);  // a crown 25 m up: 5 m under the scout
  EXPECT_EQ(out_.setpoint.kind, SetpointKind::kFlock);
  EXPECT_DOUBLE_EQ(out_.setpoint.target_m.z(), 33.0);
  EXPECT_EQ(out_.setpoint.target_m.head<2>(), scout_->lanes().front().position_m.head<2>());  // same lane
  ASSERT_EQ(CountEvents(out_, "clearance_climb"), 1);
  const LogfmtFields f = ParseLogfmt(out_.events.front().str());
  EXPECT_EQ(FindField(f, "top_z"), "25.00");
  EXPECT_EQ(FindField(f, "altitude"), "33.00");
  Step(2.2, 25.3);  // the same crown again, SGBM's noise on it: no new event
  EXPECT_DOUBLE_EQ(out_.setpoint.target_m.z(), 33.3);
  EXPECT_EQ(CountEvents(out_, "clearance_climb"), 0);
  Step(2.4, 27.0);  // a taller one: 2 m more, logged again
  EXPECT_DOUBLE_EQ(out_.setpoint.target_m.z(), 35.0);
  EXPECT_EQ(CountEvents(out_, "clearance_climb"), 1);
}

TEST_F(SafeHeight, HoldsTheRaisedAltitudeForTheHoldTimeAfterTheLastReportThenReturns) {
  SetUpScout(kMinClearance_m);
  const double hold_s = ScoutConfig{}.clearance_hold_s;
  Step(2.0, 25.0);
  ASSERT_DOUBLE_EQ(out_.setpoint.target_m.z(), 33.0);
  Step(3.0, 23.5);  // a lower crown (31.5 m asked for): it does not come down, the hold restarts
  EXPECT_DOUBLE_EQ(out_.setpoint.target_m.z(), 33.0);
  Step(3.2, 0.0);           // the ground (8 m asked for, under the search altitude): no restart
  Step(3.4, std::nullopt);  // no frame
  EXPECT_DOUBLE_EQ(out_.setpoint.target_m.z(), 33.0);
  Step(3.0 + hold_s - 0.1, 0.0);
  EXPECT_DOUBLE_EQ(out_.setpoint.target_m.z(), 33.0);
  Step(3.0 + hold_s + 0.1, 0.0);
  EXPECT_DOUBLE_EQ(out_.setpoint.target_m.z(), kSearchAltitude_m);
  EXPECT_EQ(out_.setpoint.target_m, scout_->lanes().front().position_m);
  Step(3.0 + hold_s + 0.2, 24.0);  // a new obstacle: a new climb, logged
  EXPECT_DOUBLE_EQ(out_.setpoint.target_m.z(), 32.0);
  EXPECT_EQ(CountEvents(out_, "clearance_climb"), 1);
}

TEST_F(SafeHeight, OffWithoutAMinimumClearanceOrWithoutDepth) {
  SetUpScout(0.0);  // off: an obstacle report changes nothing
  Step(2.0, 29.0);
  EXPECT_EQ(out_.setpoint.target_m, scout_->lanes().front().position_m);
  EXPECT_EQ(CountEvents(out_, "clearance_climb"), 0);
  scout_.reset();
  mission_ = {};
  SetUpScout(kMinClearance_m);  // on, but no depth
  Step(2.0, std::nullopt);
  EXPECT_EQ(out_.setpoint.target_m, scout_->lanes().front().position_m);
  Step(2.2, 21.0);  // 29 m asked for: under the search altitude
  EXPECT_EQ(out_.setpoint.target_m, scout_->lanes().front().position_m);
  EXPECT_EQ(CountEvents(out_, "clearance_climb"), 0);
}

TEST_F(SafeHeight, TheDescentOverHomeIsNotRaised) {
  SetUpScout(kMinClearance_m);
  Step(2.0, 25.0);
  ASSERT_DOUBLE_EQ(out_.setpoint.target_m.z(), 33.0);
  ASSERT_TRUE(mission_.Apply(3, raft::ReturnHome{}).accepted);
  Step(2.2, 25.0, {40, 0, 33});  // on the way home: in its layer, raised
  EXPECT_EQ(out_.mode, "returning");
  EXPECT_DOUBLE_EQ(out_.setpoint.target_m.z(), 33.0);
  Step(2.4, 25.0, {0.5, 0, 33});  // over home: down to its layer (then lands), not held up there
  EXPECT_DOUBLE_EQ(out_.setpoint.target_m.z(), kSearchAltitude_m);
}

// A scout sweeping a 90 x 40 m sector at 12 m across a stand of 8 m trees 40 m wide (every lane
// crosses it), min_clearance_m 6 m: over the trees it flies 4 m above them without depth. With the
// fake depth it sees the stand 5 m before its edge (ClearanceBelow's radius) and climbs the 2 m at
// the rig's altitude hold (0.8 /s, flocking.hpp): within 0.15 m of the 14 m after ~3.4 s, 17 m of
// flight at 5 m/s, i.e. 12 m inside the stand (obstacle_edge_m); the first lane's entry is the
// lowest point (the later lanes start raised: the 5 s hold spans the turn at the sector's edge).
constexpr double kTreesTop_m = 8.0, kScoutAltitude_m = 12.0, kSafeClearance_m = 6.0;
constexpr double kClimbEdge_m = 12.0;
constexpr double kClimbSettle_m = 0.15;

testing::MissionSimConfig StandOfTrees(bool depth) {
  testing::MissionSimConfig c;
  c.area = {-45, -20, 45, 20};
  c.drones = {{"scout_1", Role::kScout, Vec3(-28, -18, 0), 0.23}};
  c.scout_altitude_m = kScoutAltitude_m;
  c.scout_min_clearance_m = depth ? kSafeClearance_m : 0.0;
  c.fake_depth = depth;
  c.obstacles = {{.area = {-20, -30, 20, 30}, .top_z_m = kTreesTop_m}};
  c.obstacle_edge_m = kClimbEdge_m;
  return c;
}

TEST(SafeHeightScenario, ADepthCameraKeepsTheClearanceOverAStandOfTrees) {
  double inner_m[2] = {0, 0}, all_m[2] = {0, 0};
  for (const bool depth : {false, true}) {
    testing::MissionSim sim(StandOfTrees(depth));
    ASSERT_TRUE(sim.RunUntil([](const testing::MissionSim& s) { return s.Logged("sector_swept"); }, 900.0));
    inner_m[depth] = sim.min_obstacle_clearance_m(true);
    all_m[depth] = sim.min_obstacle_clearance_m(false);
    EXPECT_EQ(sim.Logged("clearance_climb"), depth);
    std::printf(
        "depth=%d: min clearance over the trees %.2f m, >= %.0f m inside their edges %.2f m, "
        "swept at t=%.1f s\n",
        depth, all_m[depth], kClimbEdge_m, inner_m[depth], sim.t_s());
  }
  EXPECT_NEAR(inner_m[0], kScoutAltitude_m - kTreesTop_m, 0.2);  // without: the 4 m the altitude leaves
  EXPECT_NEAR(all_m[0], kScoutAltitude_m - kTreesTop_m, 0.2);
  EXPECT_GE(inner_m[1], kSafeClearance_m - kClimbSettle_m);
  EXPECT_GT(all_m[1], all_m[0] + 0.5);  // even at the first entry, before the climb is done
}

}  // namespace
}  // namespace swarmbox::swarm
