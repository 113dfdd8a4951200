// Scout, lifter and leader state machines (agent/swarm/{scout_behaviour,lifter_sequence,
// leader_planner}.hpp) step by step against a raft::MissionState driven by hand.
#include <algorithm>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "swarmbox/swarm/leader_planner.hpp"
#include "swarmbox/swarm/lifter_sequence.hpp"
#include "swarmbox/swarm/scout_behaviour.hpp"
#include "swarmbox/swarm/swarm.hpp"  // the umbrella header compiles on its own

namespace swarmbox::swarm {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using raft::MissionPhase;

class Mission {
 public:
  void Apply(const raft::MissionCommand& c) {
    const raft::ApplyResult r = state.Apply(++index_, c);
    ASSERT_TRUE(r.accepted) << raft::CommandName(c) << ": " << r.reason;
  }
  raft::MissionState state;

 private:
  std::uint64_t index_ = 0;
};

MissionInput Input(double t, const Mission& m, const Vector3d& p) {
  MissionInput in;
  in.t_s = t;
  in.mission = &m.state;
  in.position_m = p;
  return in;
}

bool HasEvent(const MissionOutput& out, const std::string& name) {
  for (const LogEvent& e : out.events) {
    if (e.str().find("event=" + name) != std::string::npos) return true;
  }
  return false;
}

const raft::Sector kSector{"scout_1", 0, 0, 60, 150};

// ---- scout ---------------------------------------------------------------------------------

TEST(ScoutBehaviour, TakesOffToSearchAltitudeThenWaitsForItsSector) {
  Mission m;
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0)});
  MissionOutput out;
  s.Step(Input(0.0, m, {0, 0, 0.23}), &out);
  EXPECT_EQ(out.mode, "taking_off");
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kTakeoff);
  EXPECT_DOUBLE_EQ(out.setpoint.target_m.z(), 30.0);
  s.Step(Input(10.0, m, {0, 0, 29.5}), &out);
  EXPECT_EQ(out.mode, "awaiting_sector");
  s.Step(Input(10.1, m, {0, 0, 30}), &out);
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kFlock);  // holds over home, flocking
  m.Apply(raft::AssignSectors{{kSector}});
  m.Apply(raft::StartSearch{});
  s.Step(Input(11.0, m, {0, 0, 30}), &out);
  EXPECT_EQ(out.mode, "searching");
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kFlock);
  EXPECT_EQ(out.setpoint.target_m, s.lanes().front().position_m);
}

TEST(ScoutBehaviour, SweepsItsLanesInOrderThenReportsTheSectorSwept) {
  Mission m;
  m.Apply(raft::AssignSectors{{kSector}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0)});
  MissionOutput out;
  s.Step(Input(0.0, m, {0, 0, 0.23}), &out);
  s.Step(Input(1.0, m, {0, 0, 30}), &out);  // reaches altitude
  s.Step(Input(1.1, m, {0, 0, 30}), &out);  // its sector is there: search
  ASSERT_EQ(out.mode, "searching");
  const std::vector<Waypoint> lanes = s.lanes();
  double t = 2.0;
  bool swept_event = false;
  for (std::size_t i = 0; i < lanes.size(); ++i) {
    EXPECT_EQ(out.setpoint.target_m, lanes[i].position_m) << "waypoint " << i;
    EXPECT_DOUBLE_EQ(out.setpoint.yaw_rad, lanes[i].yaw_rad);
    s.Step(Input(t += 1.0, m, lanes[i].position_m), &out);  // arrive
    swept_event = swept_event || HasEvent(out, "sector_swept");
  }
  EXPECT_TRUE(swept_event);
  EXPECT_EQ(out.mode, "swept");
}

TEST(ScoutBehaviour, ReportsASightingOnceAndNothingNearAKnownVictim) {
  Mission m;
  m.Apply(raft::AssignSectors{{kSector}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0), .report_cooldown_s = 10.0});
  MissionOutput out;
  s.Step(Input(0.0, m, {0, 0, 0.23}), &out);
  s.Step(Input(1.0, m, {0, 0, 30}), &out);
  GroundDetection d;
  d.position_m = {20, 30, 0};
  d.confidence = 0.7;
  std::vector<GroundDetection> dets = {d};
  MissionInput in = Input(2.0, m, {0, 0, 30});
  in.detections = dets;
  s.Step(in, &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  const auto* r = std::get_if<raft::ReportSighting>(&out.proposals[0]);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->reporter, "scout_1");
  EXPECT_EQ(r->seq, 1u);
  EXPECT_DOUBLE_EQ(r->x_m, 20.0);
  EXPECT_DOUBLE_EQ(r->confidence, 0.7);
  in.t_s = 5.0;  // same place within the cooldown: silent
  s.Step(in, &out);
  EXPECT_TRUE(out.proposals.empty());
  in.t_s = 13.0;  // after the cooldown (the first report may have been lost): again, next seq
  s.Step(in, &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  EXPECT_EQ(std::get<raft::ReportSighting>(out.proposals[0]).seq, 2u);
  // Once a victim is confirmed there, no more reports of it.
  m.Apply(raft::ConfirmVictim{"operator", 21, 31});
  in.t_s = 30.0;
  s.Step(in, &out);
  EXPECT_TRUE(out.proposals.empty());
  // Below MissionState::kMinConfidence: not reported.
  dets[0].position_m = {50, 100, 0};
  dets[0].confidence = 0.4;
  s.Step(in, &out);
  EXPECT_TRUE(out.proposals.empty());
}

TEST(ScoutBehaviour, ReportsASecondViewOnceItMovedABaselineFromItsLastReport) {
  // One pass over a spot: a view every report_baseline_m of flight while it is in the footprint
  // (the second view the fusion needs), nothing in between, each with where it was seen from.
  Mission m;
  m.Apply(raft::AssignSectors{{kSector}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 1.0), .report_cooldown_s = 10.0,
                    .report_baseline_m = 10.0});
  MissionOutput out;
  s.Step(Input(0.0, m, {0, 0, 1.23}), &out);
  s.Step(Input(1.0, m, {0, 0, 31}), &out);
  GroundDetection d;
  d.position_m = {20, 30, 0};
  d.confidence = 0.75;
  d.capture_time_s = 1.96;
  d.viewer_m = {0, 20, 31};
  std::vector<GroundDetection> dets = {d};
  MissionInput in = Input(2.0, m, {0, 20, 31});
  in.detections = dets;
  s.Step(in, &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  const auto& first = std::get<raft::ReportSighting>(out.proposals[0]);
  EXPECT_DOUBLE_EQ(first.viewer_y_m, 20);
  EXPECT_DOUBLE_EQ(first.viewer_height_m, 30);  // above the home's ground
  EXPECT_DOUBLE_EQ(first.t_s, 1.96);
  dets[0].viewer_m = {0, 26, 31};  // 6 m on: the same view, silent
  dets[0].confidence = 0.97;
  in.t_s = 2.9;
  s.Step(in, &out);
  EXPECT_TRUE(out.proposals.empty());
  dets[0].viewer_m = {0, 30.5, 31};  // 10.5 m from the first: a second view
  dets[0].position_m = {20.5, 30.2, 0};
  in.t_s = 3.5;
  s.Step(in, &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  EXPECT_DOUBLE_EQ(std::get<raft::ReportSighting>(out.proposals[0]).confidence, 0.97);
  EXPECT_DOUBLE_EQ(std::get<raft::ReportSighting>(out.proposals[0]).viewer_y_m, 30.5);
  dets[0].viewer_m = {0, 36, 31};  // within the baseline of the second: silent again
  in.t_s = 4.2;
  s.Step(in, &out);
  EXPECT_TRUE(out.proposals.empty());
}

TEST(ScoutBehaviour, KeepSearchingDuringRescueOrbitsOnlyOnceSweptThenLeavesTheOrbit) {
  Mission m;
  m.Apply(raft::AssignSectors{{kSector}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0), .orbit_time_s = 20.0,
                    .keep_searching_during_rescue = true, .return_when_swept = true,
                    .approach_height_m = 5.0});
  MissionOutput out;
  s.Step(Input(0.0, m, {0, 0, 0.23}), &out);
  s.Step(Input(1.0, m, {0, 0, 30}), &out);
  s.Step(Input(1.1, m, {0, 0, 30}), &out);
  ASSERT_EQ(out.mode, "searching");
  m.Apply(raft::ConfirmVictim{"operator", 100, 100});
  m.Apply(raft::ConvergeOn{1});
  m.Apply(raft::BeginRescue{1, "lifter"});
  s.Step(Input(2.0, m, {0, 0, 30}), &out);
  EXPECT_EQ(out.mode, "searching");  // its lanes first
  double t = 2.0;
  for (std::size_t k = 0; k < s.lanes().size(); ++k) s.Step(Input(t += 0.1, m, s.lanes()[k].position_m), &out);
  EXPECT_EQ(out.mode, "orbiting");  // swept: now it orbits the victim being rescued
  const Vector3d on_orbit(88, 100, 30);
  s.Step(Input(t += 0.1, m, on_orbit), &out);
  s.Step(Input(t += 10.0, m, on_orbit), &out);
  EXPECT_EQ(out.mode, "orbiting");
  s.Step(Input(t += 10.5, m, on_orbit), &out);  // orbit_time_s on the orbit: done with it
  EXPECT_TRUE(HasEvent(out, "victim_handled"));
  s.Step(Input(t += 0.1, m, on_orbit), &out);  // nothing left: home
  EXPECT_EQ(out.mode, "returning");
  // Near home it flies over home in position mode at its altitude, then descends vertically to
  // the approach height, then lands.
  s.Step(Input(t += 30, m, {3, 3, 30}), &out);
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kPosition);
  EXPECT_EQ(out.setpoint.target_m, Vector3d(0, 0, 30));
  s.Step(Input(t += 1, m, {1.0, 1.0, 30}), &out);
  EXPECT_EQ(out.setpoint.target_m, Vector3d(0, 0, 5));
  s.Step(Input(t += 1, m, {0.2, 0.1, 29}), &out);
  EXPECT_EQ(out.mode, "returning");  // over home but still high
  s.Step(Input(t += 10, m, {0.2, 0.1, 5.4}), &out);
  EXPECT_EQ(out.mode, "landing");
}

// From the ground at home to its sector's first lane (the mission has kSector and the search
// started): taken off to 30 m, searching, at the lane's start (t 2 s), flying the lane.
void OnItsFirstLane(const Mission& m, ScoutBehaviour& s, MissionOutput& out) {
  s.Step(Input(0.0, m, {0, 0, 0.23}), &out);
  s.Step(Input(1.0, m, {0, 0, 30}), &out);
  s.Step(Input(1.1, m, {0, 0, 30}), &out);
  ASSERT_EQ(out.mode, "searching");
  s.Step(Input(2.0, m, s.lanes()[0].position_m), &out);
  ASSERT_EQ(s.lane_index(), 1u);
}

TEST(ScoutBehaviour, OrbitsTheTargetVictimAndResumesItsLaneAfterTheRescue) {
  Mission m;
  m.Apply(raft::AssignSectors{{kSector}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0)});
  MissionOutput out;
  ASSERT_NO_FATAL_FAILURE(OnItsFirstLane(m, s, out));
  ASSERT_GE(s.lanes().size(), 4u);
  m.Apply(raft::ConfirmVictim{"operator", 100, 100});
  m.Apply(raft::ConvergeOn{1});
  s.Step(Input(3.0, m, {10, 10, 30}), &out);
  EXPECT_EQ(out.mode, "orbiting");
  EXPECT_NEAR((out.setpoint.target_m.head<2>() - Vector2d(100, 100)).norm(), 15.0, 1e-9);  // on the orbit
  m.Apply(raft::BeginRescue{1, "lifter"});
  s.Step(Input(4.0, m, {85, 100, 30}), &out);
  EXPECT_EQ(out.mode, "orbiting");  // RESCUE: keep orbiting until rescued
  m.Apply(raft::MarkRescued{1});
  s.Step(Input(5.0, m, {85, 100, 30}), &out);
  EXPECT_EQ(out.mode, "searching");
  EXPECT_EQ(s.lane_index(), 1u);  // the lane it left ...
  // ... from the lane's point nearest where it left it (it left from (10, 10), off the lane) ...
  const Vector2d a = s.lanes()[0].position_m.head<2>();
  const Vector2d b = s.lanes()[1].position_m.head<2>();
  const Vector2d rejoin =
      a + std::clamp((Vector2d(10, 10) - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0) * (b - a);
  EXPECT_NEAR((out.setpoint.target_m.head<2>() - rejoin).norm(), 0.0, 1e-9);
  // ... then on along the lane.
  s.Step(Input(6.0, m, {rejoin.x(), rejoin.y(), 30}), &out);
  EXPECT_EQ(out.setpoint.target_m, s.lanes()[1].position_m);
}

// A revisit taken halfway along a lane: the sweep comes back to that point of the lane and flies
// the rest of it, rather than cutting across to the lane's end (rubble20 on 2026-11-28: r14's
// scout_1 lost two lanes so and never saw victim_3); a second revisit on the way back does not
// move the point on.
TEST(ScoutBehaviour, ARevisitMidLaneResumesTheSweepWhereItLeftTheLane) {
  Mission m;
  m.Apply(raft::AssignSectors{{kSector}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0)});
  MissionOutput out;
  ASSERT_NO_FATAL_FAILURE(OnItsFirstLane(m, s, out));
  const Vector3d start = s.lanes()[0].position_m;
  const Vector3d end = s.lanes()[1].position_m;
  const Vector3d halfway = 0.5 * (start + end);
  ASSERT_GT((end - start).head<2>().norm(), 50.0);
  // Candidate 1 far off the lane, its revisit given to this scout.
  m.Apply(raft::ReportSighting{"scout_2", 1, 200, 200, 0.8});
  m.Apply(raft::RequestRevisit{1, "scout_1"});
  s.Step(Input(3.0, m, halfway), &out);
  ASSERT_EQ(out.mode, "revisiting");
  // The revisit is answered (a view from scout_1 commits and the leader clears the request): the
  // sweep resumes, towards where it left the lane, not the lane's end.
  m.Apply(raft::ReportSighting{"scout_1", 1, 200, 200, 0.9});
  ASSERT_TRUE(m.state.FindCandidate(1)->revisit_drone.empty());
  s.Step(Input(40.0, m, {200, 200, 30}), &out);
  ASSERT_EQ(out.mode, "searching");
  EXPECT_TRUE(HasEvent(out, "mission_stage"));
  EXPECT_EQ(s.lane_index(), 1u);
  EXPECT_NEAR((out.setpoint.target_m.head<2>() - halfway.head<2>()).norm(), 0.0, 1e-9);
  // Another revisit on the way back, taken from off the lane: the rejoin point stays.
  m.Apply(raft::ReportSighting{"scout_2", 2, -100, 200, 0.8});
  m.Apply(raft::RequestRevisit{2, "scout_1"});
  s.Step(Input(41.0, m, {150, 150, 30}), &out);
  ASSERT_EQ(out.mode, "revisiting");
  m.Apply(raft::ReportSighting{"scout_1", 2, -100, 200, 0.9});
  s.Step(Input(80.0, m, {-100, 200, 30}), &out);
  ASSERT_EQ(out.mode, "searching");
  EXPECT_NEAR((out.setpoint.target_m.head<2>() - halfway.head<2>()).norm(), 0.0, 1e-9);
  // Passing the lane's end on the way back does not count it as flown.
  s.Step(Input(90.0, m, end), &out);
  EXPECT_EQ(s.lane_index(), 1u);
  // Back on the lane: on to its end.
  s.Step(Input(100.0, m, halfway), &out);
  EXPECT_EQ(out.setpoint.target_m, end);
  s.Step(Input(110.0, m, end), &out);
  EXPECT_EQ(s.lane_index(), 2u);
}

// A revisit's answer is a sight the mission state files under the revisited candidate: a
// look-alike 6 m off (within the scout's 10 m victim dedupe radius, beyond the state's 5 m
// association) is reported as the other candidate's view, and the revisit still ends with its own
// answer, here a miss (rubble20-a-r18 on 2026-11-29: the scout took the backpack for its answer,
// reported nothing of the person and hovered for the revisit's whole timeout).
TEST(ScoutBehaviour, ALookAlikeBesideTheCandidateDoesNotAnswerItsRevisit) {
  Mission m;
  m.Apply(raft::AssignSectors{{kSector}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0), .dedupe_radius_m = 10.0});
  MissionOutput out;
  ASSERT_NO_FATAL_FAILURE(OnItsFirstLane(m, s, out));
  m.Apply(raft::ReportSighting{"scout_2", 1, 200, 200, 0.8});
  m.Apply(raft::ReportSighting{"scout_2", 2, 206, 200, 0.8});
  ASSERT_EQ(m.state.candidates().size(), 2u);
  m.Apply(raft::RequestRevisit{1, "scout_1"});
  const Vector3d over(200, 200, 30);
  s.Step(Input(3.0, m, over), &out);
  ASSERT_EQ(out.mode, "revisiting");
  GroundDetection lookalike;
  lookalike.position_m = {206, 200, 0};
  lookalike.viewer_m = over;
  lookalike.confidence = 0.8;
  const std::vector<GroundDetection> dets = {lookalike};
  MissionInput in = Input(3.2, m, over);
  in.detections = dets;
  s.Step(in, &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  const auto* r = std::get_if<raft::ReportSighting>(&out.proposals[0]);
  ASSERT_NE(r, nullptr);
  EXPECT_DOUBLE_EQ(r->x_m, 206.0);
  m.Apply(*r);
  ASSERT_EQ(m.state.FindCandidate(2)->views.size(), 2u);  // filed under the look-alike's candidate
  // Nothing at the candidate for revisit_look_s: the revisit's answer is a miss of candidate 1.
  bool missed = false;
  for (double t = 3.4; t < 6.0 && !missed; t += 0.2) {
    s.Step(Input(t, m, over), &out);
    for (const raft::MissionCommand& c : out.proposals) {
      const auto* miss = std::get_if<raft::ReportMiss>(&c);
      missed = missed || (miss != nullptr && miss->candidate == 1u);
    }
  }
  EXPECT_TRUE(missed);
}

TEST(ScoutBehaviour, BatteryLowEmitsTheEventOnceThenReturnsAndLandsAtHome) {
  Mission m;
  m.Apply(raft::AssignSectors{{kSector}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(-5, -5, 0)});
  MissionOutput out;
  s.Step(Input(0.0, m, {-5, -5, 0.23}), &out);
  s.Step(Input(1.0, m, {-5, -5, 30}), &out);
  MissionInput in = Input(2.0, m, {30, 60, 30});
  in.battery_low = true;
  in.battery_fraction = 0.18;
  s.Step(in, &out);
  EXPECT_TRUE(HasEvent(out, "battery_low"));
  EXPECT_EQ(out.mode, "returning");
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kFlock);
  in.t_s = 3.0;
  s.Step(in, &out);
  EXPECT_FALSE(HasEvent(out, "battery_low"));  // once
  in.position_m = {-2, -5, 30};                  // within home_approach_m: straight home
  s.Step(in, &out);
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kPosition);
  in.position_m = {-5, -5.5, 30};
  s.Step(in, &out);
  EXPECT_EQ(out.mode, "landing");
  s.Step(in, &out);
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kLand);
  EXPECT_EQ(out.setpoint.target_m, Vector3d(-5, -5, 0));
  in.position_m = {-5, -5, 0.25};
  s.Step(in, &out);
  EXPECT_EQ(out.mode, "landed");
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kIdle);
}

// ---- lifter --------------------------------------------------------------------------------

class LifterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    m.Apply(raft::AssignSectors{{kSector}});
    m.Apply(raft::StartSearch{});
    m.Apply(raft::ConfirmVictim{"operator", 40, 0});
    m.Apply(raft::ConvergeOn{1});
    m.Apply(raft::BeginRescue{1, "lifter"});
  }
  // Steps with the drone exactly at the commanded target (an ideal flight stack).
  void StepAt(double t, const Vector3d& p, bool attached) {
    MissionInput in = Input(t, m, p);
    in.payload_attached = attached;
    lifter.Step(in, &out);
  }
  Mission m;
  LifterSequence lifter{{.name = "lifter", .home_m = Vector3d(0, 0, 0), .loading_time_s = 5.0}};
  MissionOutput out;
};

TEST_F(LifterTest, RepeatsThePayloadRequestUntilTheStatusChanges) {
  const double attach_z = lifter.config().AttachHeight();
  StepAt(0.0, {0, 0, 0.6}, false);
  EXPECT_EQ(out.mode, "takeoff_for_pickup");
  std::vector<double> request_times;
  for (int k = 1; k <= 80; ++k) {  // 8 s, hovering at the hook height over the stretcher
    const double t = 0.1 * k;
    StepAt(t, {0, 0, attach_z}, false);
    if (out.payload.action == PayloadAction::kAttach) {
      request_times.push_back(t);
      EXPECT_DOUBLE_EQ(out.payload.mass_kg, lifter.config().empty_stretcher_mass_kg);
      EXPECT_EQ(out.mode, "attach_empty");
    }
  }
  // First after settle_time_s (1.5 s) at the target, then every attach_retry_s (3 s).
  ASSERT_EQ(request_times.size(), 3u);
  EXPECT_NEAR(request_times[0], 1.6, 0.15);
  EXPECT_NEAR(request_times[1] - request_times[0], 3.0, 0.15);
  EXPECT_NEAR(request_times[2] - request_times[1], 3.0, 0.15);
  StepAt(8.1, {0, 0, attach_z}, true);
  EXPECT_EQ(out.mode, "climb");
  EXPECT_TRUE(out.setpoint.damp_swing);
}

TEST_F(LifterTest, SetsTheStretcherDownBesideTheVictimAndReattachesItLoaded) {
  const double attach_z = lifter.config().AttachHeight();
  const double transit_z = lifter.config().transit_altitude_m;
  StepAt(0.0, {0, 0, 0.6}, false);
  for (double t = 0.1; t < 2.0; t += 0.1) StepAt(t, {0, 0, attach_z}, false);
  StepAt(2.0, {0, 0, attach_z}, true);
  StepAt(2.1, {0, 0, transit_z}, true);
  ASSERT_EQ(out.mode, "transit_to_victim");
  // The drop point: stretcher_offset_m (3 m) from the victim (40, 0) toward home (0, 0).
  EXPECT_EQ(out.setpoint.target_m, Vector3d(37, 0, transit_z));
  StepAt(3.0, {37, 0, transit_z}, true);
  ASSERT_EQ(out.mode, "descend_to_release");
  const Vector3d release = out.setpoint.target_m;
  EXPECT_NEAR(release.z(), attach_z - lifter.config().release_sink_m, 1e-12);
  bool release_asked = false;
  for (double t = 3.1; t < 5.0; t += 0.1) {
    StepAt(t, release, true);
    release_asked = release_asked || out.payload.action == PayloadAction::kRelease;
  }
  ASSERT_EQ(out.mode, "release");
  EXPECT_TRUE(release_asked);
  StepAt(5.1, release, false);
  EXPECT_EQ(out.mode, "loading");
  EXPECT_TRUE(HasEvent(out, "stretcher_released"));
  EXPECT_EQ(lifter.stretcher_xy_m(), Vector2d(37, 0));
  StepAt(9.0, {37, 0, attach_z}, false);
  EXPECT_EQ(out.mode, "loading");  // loading_time_s = 5 s
  StepAt(10.2, {37, 0, attach_z}, false);
  ASSERT_EQ(out.mode, "attach_loaded");
  bool asked = false;
  for (double t = 10.3; t < 12.5 && !asked; t += 0.1) {
    StepAt(t, {37, 0, attach_z}, false);
    asked = out.payload.action == PayloadAction::kAttach;
  }
  ASSERT_TRUE(asked);
  EXPECT_DOUBLE_EQ(out.payload.mass_kg, 80.0);
  StepAt(13.0, {37, 0, attach_z}, true);
  EXPECT_EQ(out.mode, "climb_loaded");
  EXPECT_TRUE(HasEvent(out, "evacuee_loaded"));
}

TEST_F(LifterTest, ReleasesWithinTheLooserToleranceWhileTheLoadStillSwings) {
  const double attach_z = lifter.config().AttachHeight();
  const double transit_z = lifter.config().transit_altitude_m;
  StepAt(0.0, {0, 0, 0.6}, false);
  for (double t = 0.1; t < 2.0; t += 0.1) StepAt(t, {0, 0, attach_z}, false);
  StepAt(2.0, {0, 0, attach_z}, true);
  StepAt(2.1, {0, 0, transit_z}, true);
  StepAt(3.0, {37, 0, transit_z}, true);
  ASSERT_EQ(out.mode, "descend_to_release");
  const Vector3d release = out.setpoint.target_m;
  // 1.2 m off and moving at 0.8 m/s (a swinging stretcher): too loose to hook, fine to set down.
  bool asked = false;
  for (double t = 3.1; t < 6.0 && !asked; t += 0.1) {
    MissionInput in = Input(t, m, release + Vector3d(1.2, 0, 0));
    in.velocity_m_s = {0.8, 0, 0};
    in.payload_attached = true;
    lifter.Step(in, &out);
    asked = out.payload.action == PayloadAction::kRelease;
  }
  EXPECT_TRUE(asked);
  StepAt(6.1, release + Vector3d(1.2, 0, 0), false);
  EXPECT_EQ(out.mode, "loading");
  EXPECT_EQ(lifter.stretcher_xy_m(), Vector2d(38.2, 0));  // where it really came down
}

TEST_F(LifterTest, GoesBackForTheStretcherWhenTheHookTurnsOutEmpty) {
  const double attach_z = lifter.config().AttachHeight();
  StepAt(0.0, {0, 0, 0.6}, false);
  for (double t = 0.1; t < 2.0; t += 0.1) StepAt(t, {0, 0, attach_z}, false);
  StepAt(2.0, {0, 0, attach_z}, true);
  ASSERT_EQ(out.mode, "climb");
  StepAt(3.0, {0, 0, attach_z + 3}, false);  // the load check found no load
  EXPECT_EQ(out.mode, "takeoff_for_pickup");
  EXPECT_EQ(out.setpoint.target_m, Vector3d(0, 0, attach_z));
}

class StandbyLifterTest : public LifterTest {
 protected:
  StandbyLifterTest() {
    lifter = LifterSequence({.name = "lifter", .home_m = Vector3d(0, 0, 0),
                             .stretcher_start_offset_m = Vector2d(0, -3), .standby_after_delivery = true,
                             .loading_time_s = 5.0});
  }
  // Runs the rescue of victim 1 with an ideal flight stack and world until `mode`.
  double RunUntil(const std::string& mode, double t) {
    const double attach_z = lifter.config().AttachHeight();
    bool attached = false;
    for (int guard = 0; out.mode != mode && guard < 5000; ++guard) {
      t += 0.1;
      Vector3d p = out.setpoint.kind == SetpointKind::kTakeoff ? Vector3d(0, -3, attach_z) : out.setpoint.target_m;
      if (out.mode == "on_ground" || guard == 0) p = {0, 0, 0.6};
      if (out.payload.action == PayloadAction::kAttach) attached = true;
      if (out.payload.action == PayloadAction::kRelease) attached = false;
      StepAt(t, p, attached);
    }
    return t;
  }
};

TEST_F(StandbyLifterTest, PicksUpTheStretcherBesideItsSpawnThenStandsByForTheNextVictim) {
  StepAt(0.0, {0, 0, 0.6}, false);
  EXPECT_EQ(out.mode, "takeoff_for_pickup");
  EXPECT_EQ(lifter.stretcher_xy_m(), Vector2d(0, -3));  // beside the spawn, as the world lays it
  m.Apply(raft::ConfirmVictim{"operator", -30, 40});  // a second victim waits meanwhile
  double t = RunUntil("standby", 0.0);
  ASSERT_EQ(out.mode, "standby");
  ASSERT_EQ(out.proposals.size(), 1u);  // MarkRescued{1}
  m.Apply(raft::MarkRescued{1});
  m.Apply(raft::ConvergeOn{2});
  StepAt(t + 1.0, out.setpoint.target_m, false);
  EXPECT_EQ(out.mode, "standby");  // hovers over the stretcher, no landing
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kPosition);
  m.Apply(raft::BeginRescue{2, "lifter"});
  StepAt(t + 2.0, out.setpoint.target_m, false);
  EXPECT_EQ(out.mode, "takeoff_for_pickup");
  EXPECT_EQ(lifter.victim(), 2u);
}

TEST_F(StandbyLifterTest, LandsAfterDeliveryWhenNoVictimWaits) {
  StepAt(0.0, {0, 0, 0.6}, false);
  const double t = RunUntil("move_to_land", 0.0);
  EXPECT_EQ(out.mode, "move_to_land");
  EXPECT_LT(t, 400.0);
}

TEST_F(LifterTest, MarkRescuedIsReproposedUntilCommitted) {
  const double attach_z = lifter.config().AttachHeight();
  // Fast-forward through the sequence with an ideal flight stack and world.
  bool attached = false;
  double t = 0;
  int guard = 0;
  while (out.mode != "move_to_land" && ++guard < 5000) {
    t += 0.1;
    Vector3d p = out.setpoint.kind == SetpointKind::kTakeoff ? Vector3d(0, 0, attach_z) : out.setpoint.target_m;
    if (out.mode == "on_ground" || guard == 1) p = {0, 0, 0.6};
    if (out.payload.action == PayloadAction::kAttach) attached = true;
    if (out.payload.action == PayloadAction::kRelease) attached = false;
    StepAt(t, p, attached);
  }
  ASSERT_EQ(out.mode, "move_to_land");
  ASSERT_EQ(out.proposals.size(), 1u);
  EXPECT_EQ(std::get<raft::MarkRescued>(out.proposals[0]).victim_id, 1u);
  // Not committed: proposed again after proposal_retry_s, not before.
  StepAt(t + 1.0, out.setpoint.target_m, false);
  EXPECT_TRUE(out.proposals.empty());
  StepAt(t + 2.1, out.setpoint.target_m, false);
  ASSERT_EQ(out.proposals.size(), 1u);
  m.Apply(raft::MarkRescued{1});
  StepAt(t + 5.0, out.setpoint.target_m, false);
  EXPECT_TRUE(out.proposals.empty());
}

TEST_F(LifterTest, BatteryLowBeforeLoadingAbandonsTheRescueAndBringsTheStretcherHome) {
  const double attach_z = lifter.config().AttachHeight();
  StepAt(0.0, {0, 0, 0.6}, false);
  for (double t = 0.1; t < 2.0; t += 0.1) StepAt(t, {0, 0, attach_z}, false);
  StepAt(2.0, {0, 0, attach_z}, true);
  StepAt(2.1, {0, 0, 15}, true);
  ASSERT_EQ(out.mode, "transit_to_victim");
  MissionInput in = Input(3.0, m, {20, 0, 15});
  in.payload_attached = true;
  in.battery_low = true;
  lifter.Step(in, &out);
  EXPECT_TRUE(HasEvent(out, "battery_low"));
  EXPECT_TRUE(HasEvent(out, "rescue_abandoned"));
  EXPECT_EQ(out.mode, "carry_home");
  EXPECT_EQ(lifter.victim(), 0u);
  EXPECT_EQ(out.setpoint.target_m, Vector3d(0, 0, 15));
}

// The drop-spot survey (survey_drop_point): after the transit the lifter descends to survey
// height over the default drop point (37, 0), settles, asks the host for a spot with the
// stretcher's yaw, and takes the answer, or times out, before the descent.
class SurveyLifterTest : public LifterTest {
 protected:
  static constexpr double kYaw_rad = 0.4;
  SurveyLifterTest() {
    lifter = LifterSequence({.name = "lifter", .home_m = Vector3d(0, 0, 0), .loading_time_s = 5.0,
                             .survey_drop_point = true});
  }
  void StepWith(double t, const Vector3d& p, double yaw_rad, std::optional<DropSpotAnswer> answer = std::nullopt) {
    MissionInput in = Input(t, m, p);
    in.payload_attached = true;
    in.yaw_rad = yaw_rad;
    in.drop_spot = answer;
    lifter.Step(in, &out);
  }
  // Hooks the stretcher, climbs and flies to the default drop point; returns at "survey_drop_point".
  void FlyToTheDropPoint() {
    const double attach_z = lifter.config().AttachHeight();
    const double transit_z = lifter.config().transit_altitude_m;
    StepAt(0.0, {0, 0, 0.6}, false);
    for (double t = 0.1; t < 2.0; t += 0.1) StepAt(t, {0, 0, attach_z}, false);
    StepAt(2.0, {0, 0, attach_z}, true);
    StepAt(2.1, {0, 0, transit_z}, true);
    ASSERT_EQ(out.mode, "transit_to_victim");
    StepAt(3.0, {37, 0, transit_z}, true);
  }
  double survey_z() const { return lifter.config().survey_height_m; }
};

TEST_F(SurveyLifterTest, DescendsToSurveyHeightAndAsksOnceSettledWithTheStretchersYaw) {
  FlyToTheDropPoint();
  ASSERT_EQ(out.mode, "survey_drop_point");
  EXPECT_TRUE(HasEvent(out, "mission_stage"));
  EXPECT_EQ(out.setpoint.target_m, Vector3d(37, 0, survey_z()));
  EXPECT_TRUE(out.setpoint.damp_swing);
  EXPECT_FALSE(out.want_drop_spot);  // still at transit altitude
  StepWith(4.0, {37, 0, 11.0}, kYaw_rad);
  EXPECT_FALSE(out.want_drop_spot);  // descending
  StepWith(5.0, {37, 0, survey_z()}, kYaw_rad);
  ASSERT_TRUE(out.want_drop_spot);
  EXPECT_EQ(out.drop_spot_default_xy_m, Vector2d(37, 0));
  EXPECT_DOUBLE_EQ(out.drop_spot_yaw_rad, kYaw_rad);
  EXPECT_EQ(out.mode, "survey_drop_point");
  // It keeps asking, and holds the yaw it asked with though the body turns a little.
  StepWith(5.1, {37, 0, survey_z()}, kYaw_rad + 0.05);
  EXPECT_TRUE(out.want_drop_spot);
  EXPECT_DOUBLE_EQ(out.drop_spot_yaw_rad, kYaw_rad);
  EXPECT_DOUBLE_EQ(out.setpoint.yaw_rad, kYaw_rad);
}

TEST_F(SurveyLifterTest, AFoundSpotMovesTheDropPointAndTheStretcherGoesDownThere) {
  FlyToTheDropPoint();
  StepWith(5.0, {37, 0, survey_z()}, kYaw_rad);
  ASSERT_TRUE(out.want_drop_spot);
  const DropSpotAnswer answer{.found = true, .xy_m = Vector2d(37, 4), .slope_deg = 1.5, .height_m = 0.02};
  StepWith(5.2, {37, 0, survey_z()}, kYaw_rad, answer);
  EXPECT_TRUE(HasEvent(out, "drop_spot_chosen"));
  EXPECT_FALSE(out.want_drop_spot);
  EXPECT_EQ(lifter.drop_xy_m(), Vector2d(37, 4));
  const std::string line = out.events.back().str();
  EXPECT_NE(line.find("moved_m=4.00"), std::string::npos) << line;
  EXPECT_NE(line.find("slope_deg=1.5"), std::string::npos) << line;
  EXPECT_NE(line.find("default_ok=false"), std::string::npos) << line;
  // First over the new point at survey height, then down.
  EXPECT_EQ(out.mode, "survey_drop_point");
  EXPECT_EQ(out.setpoint.target_m, Vector3d(37, 4, survey_z()));
  StepWith(8.0, {37, 4, survey_z()}, kYaw_rad);
  ASSERT_EQ(out.mode, "descend_to_release");
  const Vector3d release = out.setpoint.target_m;
  EXPECT_EQ(release.head<2>(), Vector2d(37, 4));
  EXPECT_NEAR(release.z(), lifter.config().AttachHeight() - lifter.config().release_sink_m, 1e-12);
  EXPECT_DOUBLE_EQ(out.setpoint.yaw_rad, kYaw_rad);
  for (double t = 8.1; t < 10.0; t += 0.1) StepWith(t, release, kYaw_rad + 0.1);
  ASSERT_EQ(out.mode, "release");
  EXPECT_DOUBLE_EQ(out.setpoint.yaw_rad, kYaw_rad);  // the stretcher lies as surveyed
  StepAt(10.1, release, false);
  EXPECT_EQ(out.mode, "loading");
  EXPECT_EQ(lifter.stretcher_xy_m(), Vector2d(37, 4));
}

TEST_F(SurveyLifterTest, NoSpotFoundKeepsTheDefaultPoint) {
  FlyToTheDropPoint();
  StepWith(5.0, {37, 0, survey_z()}, kYaw_rad);
  StepWith(5.2, {37, 0, survey_z()}, kYaw_rad, DropSpotAnswer{.found = false});
  EXPECT_TRUE(HasEvent(out, "drop_spot_none"));
  EXPECT_EQ(lifter.drop_xy_m(), Vector2d(37, 0));
  EXPECT_EQ(out.mode, "descend_to_release");
  EXPECT_EQ(out.setpoint.target_m.head<2>(), Vector2d(37, 0));
}

TEST_F(SurveyLifterTest, NoAnswerWithinTheTimeoutDescendsUnverifiedAtTheDefaultPoint) {
  FlyToTheDropPoint();
  StepWith(5.0, {37, 0, survey_z()}, kYaw_rad);
  ASSERT_TRUE(out.want_drop_spot);
  const double timeout_s = lifter.config().survey_timeout_s;
  for (double t = 5.1; t < 5.0 + timeout_s - 0.05; t += 0.1) {
    StepWith(t, {37, 0, survey_z()}, kYaw_rad);
    ASSERT_EQ(out.mode, "survey_drop_point") << t;
    ASSERT_TRUE(out.want_drop_spot) << t;
  }
  StepWith(5.0 + timeout_s, {37, 0, survey_z()}, kYaw_rad);
  EXPECT_TRUE(HasEvent(out, "drop_spot_unverified"));
  EXPECT_NE(out.events.front().str().find("reason=no_depth"), std::string::npos) << out.events.front().str();
  EXPECT_FALSE(out.want_drop_spot);
  EXPECT_EQ(out.mode, "descend_to_release");
  EXPECT_EQ(out.setpoint.target_m.head<2>(), Vector2d(37, 0));
  // A late answer changes nothing.
  StepWith(16.0, {37, 0, 5.0}, kYaw_rad, DropSpotAnswer{.found = true, .xy_m = Vector2d(40, 0)});
  EXPECT_EQ(lifter.drop_xy_m(), Vector2d(37, 0));
  EXPECT_FALSE(HasEvent(out, "drop_spot_chosen"));
}

// Off (the default): the sequence is the one above, step for step, whatever in.drop_spot holds.
TEST_F(LifterTest, WithoutTheSurveyTheLifterNeverAsksAndIgnoresAnswers) {
  EXPECT_FALSE(lifter.config().survey_drop_point);
  const double attach_z = lifter.config().AttachHeight();
  bool attached = false;
  double t = 0;
  std::vector<std::string> modes;
  for (int guard = 1; out.mode != "move_to_land" && guard < 5000; ++guard) {
    t += 0.1;
    Vector3d p = out.setpoint.kind == SetpointKind::kTakeoff ? Vector3d(0, 0, attach_z) : out.setpoint.target_m;
    if (out.mode == "on_ground" || guard == 1) p = {0, 0, 0.6};
    if (out.payload.action == PayloadAction::kAttach) attached = true;
    if (out.payload.action == PayloadAction::kRelease) attached = false;
    MissionInput in = Input(t, m, p);
    in.payload_attached = attached;
    in.drop_spot = DropSpotAnswer{.found = true, .xy_m = Vector2d(50, 50)};
    lifter.Step(in, &out);
    EXPECT_FALSE(out.want_drop_spot);
    if (modes.empty() || modes.back() != out.mode) modes.emplace_back(out.mode);
  }
  EXPECT_EQ(std::find(modes.begin(), modes.end(), "survey_drop_point"), modes.end());
  EXPECT_NE(std::find(modes.begin(), modes.end(), "descend_to_release"), modes.end());
  EXPECT_EQ(lifter.drop_xy_m(), Vector2d(37, 0));
}

// ---- leader --------------------------------------------------------------------------------

std::vector<RosterEntry> Roster(const std::string& scout_mode, const std::string& lifter_mode) {
  return {{"scout_1", Role::kScout, scout_mode}, {"scout_2", Role::kScout, scout_mode},
          {"lifter", Role::kLifter, lifter_mode}};
}

TEST(LeaderPlanner, AssignsSectorsAndStartsOnceTheScoutsAreAirborne) {
  Mission m;
  LeaderPlanner leader({.name = "scout_1", .search_area = {-50, -50, 50, 50}, .retry_s = 3.0});
  MissionOutput out;
  leader.Step(1.0, m.state, Roster("taking_off", "on_ground"), &out);
  EXPECT_TRUE(out.proposals.empty());
  leader.Step(2.0, m.state, Roster("awaiting_sector", "on_ground"), &out);
  ASSERT_EQ(out.proposals.size(), 2u);
  const auto& assign = std::get<raft::AssignSectors>(out.proposals[0]);
  ASSERT_EQ(assign.sectors.size(), 2u);  // scouts only, sorted by name
  EXPECT_EQ(assign.sectors[0].drone, "scout_1");
  EXPECT_EQ(assign.sectors[1].drone, "scout_2");
  EXPECT_TRUE(std::holds_alternative<raft::StartSearch>(out.proposals[1]));
  out.Clear();
  leader.Step(3.0, m.state, Roster("awaiting_sector", "on_ground"), &out);
  EXPECT_TRUE(out.proposals.empty());  // within retry_s
  leader.Step(5.5, m.state, Roster("awaiting_sector", "on_ground"), &out);
  EXPECT_EQ(out.proposals.size(), 2u);  // not committed yet: retried
}

TEST(LeaderPlanner, ConvergesOnAConfirmedVictimThenSendsTheLifter) {
  Mission m;
  m.Apply(raft::StartSearch{});
  m.Apply(raft::ConfirmVictim{"operator", 10, 10});
  LeaderPlanner leader({.name = "scout_1", .search_area = {-50, -50, 50, 50}});
  MissionOutput out;
  leader.Step(1.0, m.state, Roster("searching", "on_ground"), &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  EXPECT_EQ(std::get<raft::ConvergeOn>(out.proposals[0]).victim_id, 1u);
  m.Apply(out.proposals[0]);
  out.Clear();
  leader.Step(2.0, m.state, Roster("orbiting", "on_ground"), &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  const auto& rescue = std::get<raft::BeginRescue>(out.proposals[0]);
  EXPECT_EQ(rescue.victim_id, 1u);
  EXPECT_EQ(rescue.lifter, "lifter");
}

TEST(LeaderPlanner, ReturnsHomeWhenAllIsDoneThenCompletesAndReportsOnce) {
  Mission m;
  m.Apply(raft::StartSearch{});
  m.Apply(raft::ConfirmVictim{"operator", 10, 10});
  m.Apply(raft::ConvergeOn{1});
  m.Apply(raft::BeginRescue{1, "lifter"});
  LeaderPlanner leader({.name = "scout_1", .search_area = {-50, -50, 50, 50}});
  leader.Track(-20.0, m.state);  // followed the committed state for a while (sectors settled)
  MissionOutput out;
  leader.Step(1.0, m.state, Roster("swept", "carry_home"), &out);
  EXPECT_TRUE(out.proposals.empty());  // RESCUE: the lifter finishes it
  m.Apply(raft::MarkRescued{1});
  leader.Step(2.0, m.state, Roster("searching", "landing"), &out);
  EXPECT_TRUE(out.proposals.empty());  // a scout is still searching
  leader.Step(3.0, m.state, Roster("swept", "on_ground"), &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<raft::ReturnHome>(out.proposals[0]));
  m.Apply(out.proposals[0]);
  out.Clear();
  leader.Step(4.0, m.state, Roster("returning", "on_ground"), &out);
  EXPECT_TRUE(out.proposals.empty());
  leader.Step(5.0, m.state, Roster("landed", "on_ground"), &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  m.Apply(out.proposals[0]);
  out.Clear();
  leader.Step(6.0, m.state, Roster("landed", "on_ground"), &out);
  EXPECT_TRUE(HasEvent(out, "mission_complete"));
  EXPECT_NE(out.events[0].str().find("victims=1 rescued=1"), std::string::npos) << out.events[0].str();
  out.Clear();
  leader.Step(7.0, m.state, Roster("landed", "on_ground"), &out);
  EXPECT_FALSE(HasEvent(out, "mission_complete"));
}

}  // namespace
}  // namespace swarmbox::swarm
