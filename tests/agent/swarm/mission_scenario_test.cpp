// The SAR mission behaviours (scout_behaviour, lifter_sequence, leader_planner) in closed loop with
// the real raft::MissionState on the kinematic rig (mission_sim.hpp). Seeds fixed; tolerances in
// the assertions. These check the mission contract: take off, sectors from the leader,
// lawnmower sweeps, sightings -> confirmed victims (MissionState's confirmation rule), scouts
// converge and orbit, the lifter's stretcher sequence, battery_low, event=mission_complete.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mission_sim.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::swarm {
namespace {

using testing::MissionSim;
using testing::MissionSimConfig;
using testing::SimDrone;

MissionSimConfig BaseConfig() {
  MissionSimConfig c;
  c.drones = {{"scout_1", Role::kScout, Vec3(-90, -55, 0), 0.23},
              {"scout_2", Role::kScout, Vec3(-87, -55, 0), 0.23},
              {"scout_3", Role::kScout, Vec3(-84, -55, 0), 0.23}};
  c.victims_m = {Vec2(-40, 20), Vec2(60, -30)};
  return c;
}

// The stages one drone went through, from its event=mission_stage lines.
std::vector<std::string> Stages(const MissionSim& sim, const std::string& node) {
  std::vector<std::string> out;
  for (const std::string& line : sim.log()) {
    const LogfmtFields f = ParseLogfmt(line);
    if (FindField(f, "node") == node && FindField(f, "event") == "mission_stage") {
      out.push_back(*FindField(f, "stage"));
    }
  }
  return out;
}

bool AllDown(const MissionSim& sim, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (sim.mode(i) != "landed" && sim.mode(i) != "on_ground") return false;
  }
  return true;
}

TEST(MissionScenario, ScoutsAndALifterFindAndRescueEveryVictim) {
  MissionSimConfig c = BaseConfig();
  c.drones.push_back({"lifter", Role::kLifter, Vec3(-80, -58, 0), 0.6});
  MissionSim sim(c);
  const bool complete = sim.RunUntil([](const MissionSim& s) { return s.Logged("mission_complete"); }, 2000.0);
  ASSERT_TRUE(complete) << "no mission_complete by t=" << sim.t_s() << ", phase "
                        << raft::PhaseName(sim.mission().phase());
  RecordProperty("mission_complete_sim_s", std::to_string(sim.t_s()));
  // Every victim confirmed once, near its true position, and rescued.
  ASSERT_EQ(sim.mission().victims().size(), c.victims_m.size());
  for (const raft::Victim& v : sim.mission().victims()) {
    EXPECT_EQ(v.status, raft::VictimStatus::kRescued) << "victim " << v.id;
    EXPECT_EQ(v.rescuer, "lifter");
    double best = 1e9;
    for (const Vec2& truth : c.victims_m) best = std::min(best, (truth - Vec2(v.x_m, v.y_m)).norm());
    EXPECT_LT(best, 2.0) << "victim " << v.id;  // fake camera sigma 0.5 m per axis
  }
  EXPECT_EQ(sim.mission().phase(), raft::MissionPhase::kComplete);
  EXPECT_TRUE(AllDown(sim, c.drones.size()));
  // The stretcher is home (set down at the lifter's home), carrying the 80 kg mass last attached.
  EXPECT_LT((sim.stretcher_m() - c.drones.back().home_m.head<2>()).norm(), 0.6);
  EXPECT_FALSE(sim.stretcher_attached());
  EXPECT_DOUBLE_EQ(sim.stretcher_mass_kg(), 80.0);
  // Each scout swept its sector and orbited a victim.
  for (const char* scout : {"scout_1", "scout_2", "scout_3"}) {
    const std::vector<std::string> st = Stages(sim, scout);
    EXPECT_EQ(st.front(), "taking_off") << scout;
    EXPECT_NE(std::find(st.begin(), st.end(), "searching"), st.end()) << scout;
    EXPECT_NE(std::find(st.begin(), st.end(), "orbiting"), st.end()) << scout;
    EXPECT_NE(std::find(st.begin(), st.end(), "swept"), st.end()) << scout;
    EXPECT_EQ(st.back(), "landed") << scout;
  }
  // The lifter's explicit rescue sequence, once per victim.
  const std::vector<std::string> one_rescue = {
      "takeoff_for_pickup", "attach_empty", "climb", "transit_to_victim", "descend_to_release",
      "release", "loading", "attach_loaded", "climb_loaded", "carry_home", "descend_to_drop",
      "release_at_home", "move_to_land", "landing", "on_ground"};
  std::vector<std::string> expected;
  for (std::size_t i = 0; i < c.victims_m.size(); ++i) {
    expected.insert(expected.end(), one_rescue.begin(), one_rescue.end());
  }
  EXPECT_EQ(Stages(sim, "lifter"), expected);
  // Flocking never brought two scouts closer than the 3 m they start at (homes 3 m apart; the
  // lifter flies 15 m below them); take-offs and landings are vertical at those homes.
  EXPECT_GT(sim.min_flocking_pair_distance_m(), 2.95);
  EXPECT_GT(sim.min_pair_distance_m(), 2.0);
}

// With the drop-spot survey: the lifter stops at survey height over each default drop point, the
// fake depth host answers a spot 4 m aside, the stretcher goes down there, and the rescues complete
// as before; with no depth at all the survey times out and the default point is used.
std::vector<std::string> SurveyRescueStages() {
  return {"takeoff_for_pickup", "attach_empty", "climb", "transit_to_victim", "survey_drop_point",
          "descend_to_release", "release", "loading", "attach_loaded", "climb_loaded", "carry_home",
          "descend_to_drop", "release_at_home", "move_to_land", "landing", "on_ground"};
}

std::size_t CountEvents(const MissionSim& sim, const std::string& event) {
  return static_cast<std::size_t>(std::count_if(sim.log().begin(), sim.log().end(), [&](const std::string& line) {
    return FindField(ParseLogfmt(line), "event") == event;
  }));
}

TEST(MissionScenario, TheLifterSurveysEachDropPointAndSetsTheStretcherDownWhereTheDepthSays) {
  MissionSimConfig c = BaseConfig();
  c.drones.push_back({"lifter", Role::kLifter, Vec3(-80, -58, 0), 0.6});
  c.lifter_survey_drop_point = true;
  c.drop_spot_offset_m = Vec2(0.0, 4.0);
  MissionSim sim(c);
  ASSERT_TRUE(sim.RunUntil([](const MissionSim& s) { return s.Logged("mission_complete"); }, 2000.0));
  for (const raft::Victim& v : sim.mission().victims()) EXPECT_EQ(v.status, raft::VictimStatus::kRescued);
  std::vector<std::string> expected;
  for (std::size_t i = 0; i < c.victims_m.size(); ++i) {
    const std::vector<std::string> one = SurveyRescueStages();
    expected.insert(expected.end(), one.begin(), one.end());
  }
  EXPECT_EQ(Stages(sim, "lifter"), expected);
  EXPECT_EQ(CountEvents(sim, "drop_spot_chosen"), c.victims_m.size());
  EXPECT_EQ(CountEvents(sim, "drop_spot_unverified"), 0u);
  // Each stretcher went down at the chosen spot: 4 m from the default point, which is 3 m from
  // the victim toward home.
  for (const std::string& line : sim.log()) {
    const LogfmtFields f = ParseLogfmt(line);
    if (FindField(f, "event") != "drop_spot_chosen") continue;
    EXPECT_EQ(FindField(f, "moved_m"), "4.00") << line;
  }
  const std::string released = sim.FirstLine("stretcher_released");
  const std::string chosen = sim.FirstLine("drop_spot_chosen");
  const LogfmtFields r = ParseLogfmt(released), ch = ParseLogfmt(chosen);
  EXPECT_EQ(FindField(r, "x"), FindField(ch, "x")) << released << "\n" << chosen;
  EXPECT_EQ(FindField(r, "y"), FindField(ch, "y")) << released << "\n" << chosen;
  EXPECT_GT(sim.FirstTime("stretcher_released"), sim.FirstTime("drop_spot_chosen"));
}

TEST(MissionScenario, WithoutDepthTheLiftersSurveyTimesOutAndKeepsTheDefaultDropPoint) {
  MissionSimConfig c = BaseConfig();
  c.drones.push_back({"lifter", Role::kLifter, Vec3(-80, -58, 0), 0.6});
  c.lifter_survey_drop_point = true;  // and no drop_spot_offset_m: nobody answers
  MissionSim sim(c);
  ASSERT_TRUE(sim.RunUntil([](const MissionSim& s) { return s.Logged("mission_complete"); }, 2000.0));
  for (const raft::Victim& v : sim.mission().victims()) EXPECT_EQ(v.status, raft::VictimStatus::kRescued);
  EXPECT_EQ(CountEvents(sim, "drop_spot_unverified"), c.victims_m.size());
  EXPECT_EQ(CountEvents(sim, "drop_spot_chosen"), 0u);
  EXPECT_NE(sim.FirstLine("drop_spot_unverified").find("reason=no_depth"), std::string::npos);
}

TEST(MissionScenario, WithoutALifterScoutsOrbitEachVictimThenComplete) {
  MissionSim sim(BaseConfig());
  ASSERT_TRUE(sim.RunUntil([](const MissionSim& s) { return s.Logged("mission_complete"); }, 2000.0));
  EXPECT_EQ(sim.mission().victims().size(), 2u);
  EXPECT_TRUE(sim.Logged("victim_handled"));
  for (const raft::Victim& v : sim.mission().victims()) EXPECT_EQ(v.status, raft::VictimStatus::kConfirmed);
  EXPECT_TRUE(AllDown(sim, 3));
  EXPECT_GT(sim.min_flocking_pair_distance_m(), 2.95);
  EXPECT_GT(sim.min_pair_distance_m(), 2.0);
}

TEST(MissionScenario, BatteryLowSendsEveryScoutHomeAndTheMissionEnds) {
  MissionSimConfig c = BaseConfig();
  c.victims_m.clear();
  c.battery_drain_per_s = 0.8 / 60.0;  // 100% -> 20% in 60 s: low during the search
  MissionSim sim(c);
  ASSERT_TRUE(sim.RunUntil([](const MissionSim& s) { return s.Logged("mission_complete"); }, 600.0));
  int low_events = 0;
  for (const std::string& l : sim.log()) low_events += l.find("event=battery_low") != std::string::npos ? 1 : 0;
  EXPECT_EQ(low_events, 3);  // once per scout
  for (const char* scout : {"scout_1", "scout_2", "scout_3"}) {
    const std::vector<std::string> st = Stages(sim, scout);
    EXPECT_NE(std::find(st.begin(), st.end(), "returning"), st.end()) << scout;
    EXPECT_EQ(st.back(), "landed") << scout;
  }
  // Landed at home.
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_LT((sim.position(i).head<2>() - c.drones[i].home_m.head<2>()).norm(), 1.5);
  }
}


// ---- losing a drone (issue #8) -------------------------------------------------------------

// The lifter's config for the failure scenarios: victims in every strip of the area.
MissionSimConfig FailureConfig() {
  MissionSimConfig c = BaseConfig();
  c.drones.push_back({"lifter", Role::kLifter, Vec3(-80, -58, 0), 0.6});
  c.victims_m = {Vec2(-40, 20), Vec2(60, -30)};  // scout_3's strip is x in [33, 100]
  return c;
}

// Runs to the first event=sector_progress of `drone`, then kills it (or silences it until
// `back_s` after that); runs on to mission_complete and checks the ending.
void RunWithOutage(MissionSim& sim, const std::string& drone, bool killed, double back_after_s) {
  ASSERT_TRUE(sim.RunUntil([&](const MissionSim& s) { return s.FirstTime("sector_progress", "node=" + drone) >= 0; },
                           600.0));
  const double at = sim.t_s();
  sim.AddOutage({drone, at, at + back_after_s, killed});
  const bool complete = sim.RunUntil([](const MissionSim& s) { return s.Logged("mission_complete"); }, 3000.0);
  ASSERT_TRUE(complete) << "no mission_complete by t=" << sim.t_s() << ", phase "
                        << raft::PhaseName(sim.mission().phase());
  // Every victim found and rescued, nobody owns a sector it did not sweep.
  ASSERT_EQ(sim.mission().victims().size(), 2u);
  for (const raft::Victim& v : sim.mission().victims()) EXPECT_EQ(v.status, raft::VictimStatus::kRescued);
  const double lost = sim.FirstTime("member_lost", "drone=" + drone);
  const double handed = sim.FirstTime("sector_reassigned", "from=" + drone);
  EXPECT_GE(lost, at + 6.0 - 0.3);  // member_timeout_s after its last state (heard 0.2 s late)
  EXPECT_GE(handed, lost);
  for (const raft::Sector& s : sim.mission().sectors()) EXPECT_NE(s.drone, drone);
  std::printf("%s lost at %.1f s: member_lost %.1f s, sector_reassigned %.1f s, mission_complete %.1f s\n",
              drone.c_str(), at, lost, handed, sim.FirstTime("mission_complete"));
}

TEST(MissionFailure, AScoutKilledMidSweepHasItsSectorSweptByTheOthers) {
  MissionSim sim(FailureConfig());
  RunWithOutage(sim, "scout_3", true, 0.0);
  // The strip scout_3 never finished went to the two live scouts, who swept it.
  const std::string handed = sim.FirstLine("sector_reassigned", "from=scout_3");
  EXPECT_NE(handed.find("to=scout_1,scout_2"), std::string::npos) << handed;
  int swept = 0;
  for (const std::string& l : sim.log()) {
    swept += l.find("event=sector_swept") != std::string::npos && l.find("node=scout_3") == std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(swept, 4);  // two own strips, two pieces of scout_3's
  EXPECT_TRUE(AllDown(sim, 2));
}

TEST(MissionFailure, TheLeaderKilledMidSweepANewLeaderFinishesTheMission) {
  MissionSim sim(FailureConfig());
  RunWithOutage(sim, "scout_1", true, 0.0);
  EXPECT_EQ(sim.leader(), 1u);  // scout_2 leads now
  const std::string handed = sim.FirstLine("sector_reassigned", "from=scout_1");
  EXPECT_NE(handed.find("node=scout_2"), std::string::npos) << handed;  // the new leader did it
}

TEST(MissionFailure, AScoutSilentPastTheTimeoutComesBackAndTheMissionCompletes) {
  MissionSim sim(FailureConfig());
  RunWithOutage(sim, "scout_3", false, 20.0);
  EXPECT_TRUE(sim.Logged("member_back"));
  EXPECT_TRUE(AllDown(sim, 4));  // scout_3 too: it idled without a sector, then went home
}

}  // namespace
}  // namespace swarmbox::swarm
