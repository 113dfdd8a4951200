// The SAR mission at swarm scale on the kinematic rig (mission_sim.hpp): N scouts take off from
// the trial's 4 m grid (columns = ceil(sqrt(N)), dsl/README.md "Drone groups") on a search area scaled with
// the swarm (geofence sqrt(N) x 60 m per side, the search area 8 m in from it, as SarBrain does),
// one AssignSectors for all of them, the sweep, and event=mission_complete. Each size prints its
// mission time (simulated) and the closest approach of two airborne drones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <variant>
#include <vector>

#include "mission_sim.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::swarm {
namespace {

using testing::MissionSim;
using testing::MissionSimConfig;

MissionSimConfig Scaled(int scouts, bool lifter) {
  MissionSimConfig c;
  const double side = std::sqrt(static_cast<double>(scouts)) * 60.0;
  c.geofence_m = Vec2(side, side);
  c.area = {-side / 2 + 8, -side / 2 + 8, side / 2 - 8, side / 2 - 8};
  const int cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(scouts))));
  for (int i = 0; i < scouts; ++i) {
    c.drones.push_back(
        {"scout_" + std::to_string(i + 1), Role::kScout, Vec3(4.0 * (i % cols), 4.0 * (i / cols), 0), 0.23});
  }
  c.agent_tuning = true;
  c.takeoff_wave_s = 1.5;
  if (lifter) c.drones.push_back({"lifter", Role::kLifter, Vec3(0, -10, 0), 0.6});
  // The two victims of trials/worlds/open_field.yaml (world_size_m scales the geofence only).
  c.victims_m = {Vec2(35, 20), Vec2(-42, 55)};
  return c;
}

struct Outcome {
  bool complete = false;
  double t_s = 0;
  std::size_t assign_proposals = 0;
};

Outcome RunMission(MissionSim& sim, double max_s) {
  Outcome o;
  o.complete = sim.RunUntil([](const MissionSim& s) { return s.Logged("mission_complete"); }, max_s);
  o.t_s = sim.t_s();
  for (const std::string& line : sim.log())
    o.assign_proposals += line.find("event=sector_reassigned") != std::string::npos;
  return o;
}

class MissionAtScale : public ::testing::TestWithParam<int> {};

TEST_P(MissionAtScale, EveryScoutSearchesItsCellAndTheMissionCompletes) {
  const int n = GetParam();
  const MissionSimConfig c = Scaled(n, /*lifter=*/true);
  MissionSim sim(c);
  const Outcome o = RunMission(sim, 1500.0);
  ASSERT_TRUE(o.complete) << "no mission_complete by t=" << sim.t_s() << ", phase "
                          << raft::PhaseName(sim.mission().phase());
  // One sector per scout from the one initial proposal, nothing handed over (nobody was lost).
  EXPECT_EQ(o.assign_proposals, 0u);
  std::size_t started = 0;
  for (const std::string& line : sim.log()) started += line.find("event=sector_started") != std::string::npos;
  EXPECT_EQ(started, static_cast<std::size_t>(n));
  // Every victim found and rescued; every drone landed.
  ASSERT_EQ(sim.mission().victims().size(), c.victims_m.size());
  for (const raft::Victim& v : sim.mission().victims()) EXPECT_EQ(v.status, raft::VictimStatus::kRescued);
  for (std::size_t i = 0; i < c.drones.size(); ++i) {
    EXPECT_TRUE(sim.mode(i) == "landed" || sim.mode(i) == "on_ground")
        << c.drones[i].name << " " << sim.mode(i);
  }
  // No contact (x500 collision box 0.62 m): the take-off is vertical in 4 waves (TakeoffWave),
  // the cells are handed out in the order of the grid (no crossing paths on the way out),
  // flocking keeps the spacing in the air, and the way home is flown in 4 altitude layers with a
  // vertical descent over home, flocking until 3 m from it (a position-mode leg from 10 m out
  // crossed the columns of neighbours descending over their homes: 0.81 m at 25 scouts once
  // sightings needed a second view, #19). Measured (closest approach of two airborne drones):
  // 25 scouts 4.05 m, 49 scouts 3.06 m, 100 scouts 2.17 m, all while flocking.
  EXPECT_GT(sim.min_pair_distance_m(), 1.2);
  std::printf(
      "scouts=%d mission_s=%.1f search_done_s=%.1f min_pair_m=%.2f min_flock_pair_m=%.2f closest: %s\n", n,
      o.t_s, sim.FirstTime("mission_state", "state=RETURN"), sim.min_pair_distance_m(),
      sim.min_flocking_pair_distance_m(), sim.min_pair_where().c_str());
  RecordProperty("mission_s", std::to_string(o.t_s));
}

INSTANTIATE_TEST_SUITE_P(Scouts, MissionAtScale, ::testing::Values(25, 49, 100));

}  // namespace
}  // namespace swarmbox::swarm
