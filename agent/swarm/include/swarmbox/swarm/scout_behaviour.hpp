// ScoutBehaviour: a scout's part of the SAR mission as a pure state machine.
//
// Stages (mode strings in quotes, published as bus::DroneState::mode):
//   kOnGround "on_ground" --(t >= takeoff_delay_s, mission not over)--> kTakingOff "taking_off"
//   --(at search altitude)--> kAwaitingSector "awaiting_sector" (hold over home)
//   --(own sector committed, phase SEARCH/CONVERGE/RESCUE)--> kSearching "searching"
//       (lawnmower over the sector, swath from the camera footprint, flocking keeps spacing;
//       event=sector_started, event=sector_progress after each lane)
//   --(last lane done)--> kSwept "swept" (loiter at the sector centre)
//   A drone may own several sectors (the leader hands a lost drone's sector to live scouts): they
//   are swept one after the other in committed order, and "swept" means all of them. A sector
//   handed over after this scout finished sends it back to work: from "swept", from "returning"
//   (not for a low battery) and from "landed" (it takes off again).
//   any of the three --(phase CONVERGE/RESCUE with a target victim not rescued)--> kOrbiting
//       "orbiting" around it; back to searching when it is rescued (or, with no lifter in the
//       trial, after orbit_time_s on the orbit: the victim is then handled)
//   (keep_searching_during_rescue: only a scout with its sector swept orbits; return_when_swept:
//    "swept" with no victim to orbit goes straight to "returning")
//   any mission stage (and "returning"/"landed" when not for a low battery) --(a committed
//       revisit of a pending candidate for this drone)--> kRevisiting "revisiting": fly over the
//       candidate at search altitude (descending to revisit_look_altitude_m over it, when set),
//       look revisit_look_s with it under the camera; a detection
//       there is reported as a sighting, nothing is reported as a raft ReportMiss (with where it
//       looked from); back to what it did once the committed state shows the revisit done,
//       decided or given to another drone. The sweep resumes where it left its lane (a revisit or
//       an orbit taken mid-lane: it flies back to the point of the lane it left from, then on
//       along the lane; mission_stage stage=searching carries rejoin_x/rejoin_y), so a lane's
//       unflown part is never cut short by a diagonal to the lane's end
//   airborne --(phase RETURN/COMPLETE, or battery low: event=battery_low)--> kReturning
//       "returning" --(over home)--> kLanding "landing" --(touch-down)--> kLanded "landed".
// Detections (after the latency queue) become Raft ReportSighting proposals with their viewpoint
// (camera position, height, capture time), except near a confirmed victim or near the drone's own
// recent report of the place (cooldown) taken from within report_baseline_m, and only in an active
// phase: one pass over a spot sends a view every report_baseline_m of flight while it is in the
// footprint, the second views the leader's fusion needs (sighting_fusion.hpp; no single view
// confirms).
// Safe height (issue #23; ScoutConfig::min_clearance_m > 0): the host feeds the highest surface
// under and around the scout from its downward depth camera (MissionInput::obstacle_top_z_m,
// agent/depth ClearanceBelow). Wherever the scout commands its cruise altitude (waiting for a
// sector, searching, swept, orbiting, revisiting, and on the way home in its return layer; not
// the take-off climb nor the descent over home), the commanded altitude becomes
// max(cruise altitude, obstacle_top_z_m + min_clearance_m) (event=clearance_climb with top_z and
// the new altitude when a climb starts, and again when a taller obstacle raises it by 1 m or more).
// It never comes down during the raise: it holds the highest altitude asked for until
// clearance_hold_s of simulated time have passed without a report asking for more than the
// cruise altitude, then returns to the cruise altitude (no bobbing over each crown of a stand of
// trees). A revisit looks from the raised altitude. With min_clearance_m == 0 or no
// obstacle_top_z_m, nothing changes. What the camera gives (clearance.hpp): only obstacles within
// its 15 m range are reported, so min_clearance_m must stay below 15 m minus SGBM's error there
// (~1.3 m); looking straight down it sees an obstacle only ~0.59 x its range ahead of the nadir
// (3.5 m for a crown 6 m below), so this holds a height over things, it does not avoid flying
// into something taller than the scout: the search altitude must clear every obstacle by itself.
// A report is re-proposed (next seq) every report_retry_s until the committed state shows it (a
// pending sighting with its seq, or a victim there), at most report_tries times: a proposal
// forwarded over the lossy radio, or caught in the leader's log when the leader died, is lost
// without a word, and nobody else may pass over that spot again.
//
//   ScoutBehaviour scout({.name = "scout_1", .home_m = spawn});
//   scout.Step(input, &output);   // each mission tick (e.g. 10 Hz)
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "swarmbox/swarm/mission_types.hpp"
#include "swarmbox/swarm/search_pattern.hpp"

namespace swarmbox::swarm {

// A revisit's look counts from within this of its look altitude (the "under" check), and only a
// detection from at most this above it answers the revisit [m].
inline constexpr double kRevisitHeightToleranceM = 2.0;

struct ScoutConfig {
  std::string name;
  Eigen::Vector3d home_m = Eigen::Vector3d::Zero();  // spawn point on the ground, world ENU [m]
  double base_height_m = 0.23;        // body origin above the ground when landed [m]
  double search_altitude_m = 30.0;    // above home_m.z [m]
  double takeoff_delay_s = 0.0;
  // Camera (airframe camera spec) and sweep.
  double hfov_rad = 1.2;
  int width_px = 320;
  int height_px = 240;
  double overlap = 0.2;               // side overlap of neighbouring swaths [-]
  double waypoint_radius_m = 4.0;     // a lane waypoint counts as reached within this [m]
  double cruise_speed_m_s = 5.0;
  // Orbit around a confirmed victim.
  double orbit_radius_m = 15.0;
  int orbit_points = 12;
  double orbit_lead_rad = 0.5;
  bool lifter_present = true;         // the trial has an x8_heavy lifter
  double orbit_time_s = 30.0;         // without a lifter: orbit this long, then resume [s]
  // With keep_searching_during_rescue, only a scout whose sector is swept (or that has none)
  // converges on and orbits the target; the others finish their sweep first (faster search).
  bool keep_searching_during_rescue = false;
  // With return_when_swept, a scout with its sector swept and no victim to orbit flies home and
  // lands at once instead of loitering over its sector until RETURN.
  // It also leaves an orbit after orbit_time_s (the victim is marked, the lifter is on its way).
  bool return_when_swept = false;
  // Return and landing.
  double home_approach_m = 10.0;      // stop flocking and fly straight home within this [m]
  // Altitude layer of the way home: fly home return_layer x return_layer_m above the search
  // altitude, and descend only once over home. The agent gives each scout its TakeoffWave as its
  // layer (4 layers, 4 m apart): the 8 grid neighbours of a home are all in other layers, so two
  // scouts that swap sides on the way back (orbiting the same victim scrambles the order the
  // sectors were handed out in) pass >= 4 m above each other instead of through each other
  // (the kinematic rig saw 0.4 m at 49 scouts without layers).
  int return_layer = 0;
  double return_layer_m = 4.0;
  double home_reached_m = 1.0;
  // > 0: descend to this height above home (position mode, faster than the landing descent)
  // before landing; 0: land from the search altitude [m].
  double approach_height_m = 0.0;
  // Sightings.
  double min_report_confidence = raft::MissionState::kMinConfidence;
  // Detections outside this are not reported [m, ENU]: SarBrain passes the geofence, beyond which
  // no drone may fly (nobody could be revisited or rescued there). A frame at the field's edge sees
  // past it: rubble20 on 2026-11-28 revisited a false alarm 2.6 m outside the fence 14 times.
  Rect sighting_area{-1e9, -1e9, 1e9, 1e9};
  double dedupe_radius_m = raft::MissionState::kConfirmRadiusM;
  double report_cooldown_s = 10.0;    // re-report the same place after this (a lost proposal) [s]
  // ... or sooner once this far from every own report of it: a second view for the fusion
  // (FusionParams::min_baseline_m has why 10 m) [m].
  double report_baseline_m = 10.0;
  // Revisit: the candidate counts as under the camera within this of the nadir and 2 m of the
  // search altitude; look this long (10 frames at the x500's 5 Hz) before reporting a miss.
  double revisit_arrive_m = 2.0;
  double revisit_look_s = 2.0;
  // > 0: the close look. A revisit flies out at the search altitude and, within home_approach_m
  // of the spot, descends to this height above home to look (at 18 m the x500's camera sees the
  // spot at 26 px/m instead of 16; FusionParams::close_look_height_m counts such views as close
  // looks); only a detection from within 2 m of it answers the revisit (the descent's frames
  // from higher up are not reported near the candidate). 0: look from the search altitude [m].
  // SarBrain: 18 m, 3 m over the generator's tallest tree (15 m).
  double revisit_look_altitude_m = 0.0;
  // A revisit flies the last this many metres to its spot in position mode, not flocking (at
  // least home_approach_m), and descends to the look altitude on the way. Added when a revisit on
  // rubble20 (2026-11-28) waited 40 s 3.4 m off its candidate, each time, for 10 minutes: the
  // flocking's cohesion toward the far-off others balanced its braking migration there (fixed in
  // Flocking::Step since). SarBrain: swarm::WallStandoffM + 5 m (17.45 m) [m].
  double revisit_approach_m = 0.0;
  // Where a revisit can hover [m, ENU]: a candidate outside it (a detection near the geofence,
  // where the flocking's wall repulsion keeps the drone out) is looked at from the nearest point
  // inside, which still has it in the camera's footprint (41 x 23 m at 30 m); the miss carries
  // that viewpoint and counts if it is within FusionParams::miss_in_view_m. Flying to the spot
  // itself never arrived there: every revisit timed out and went to the next drone, for ever
  // (rubble20 on 2026-11-28: 4 of 12 trials timed out so, candidates 3-6 m from the fence, the
  // drones held ~10 m off). SarBrain sets it to the geofence shrunk by swarm::WallStandoffM.
  // A spot more than miss_in_view_m from the candidate still ends the revisit; its miss does not
  // count, so such a candidate is rejected undecided after max_revisits. Default: everywhere.
  Rect revisit_area{-1e9, -1e9, 1e9, 1e9};
  double report_retry_s = 5.0;        // re-propose a report not yet in the committed state [s]
  int report_tries = 4;               // proposals of one report at most
  std::uint64_t first_sighting_seq = 1;  // after an agent restart: seed above any used (sim ms)
  // Safe height (above): the least clearance over the highest surface the depth camera reports,
  // world z above obstacle_top_z_m [m]; 0 = off (cruise altitude only).
  double min_clearance_m = 0;
  // How long a raised altitude is held after the last report asking for it [s, simulated]: 5 s
  // is 25 m at the 5 m/s cruise (35 m at SarBrain's 7), more than the gaps between crowns in a
  // stand of trees or between rubble heaps, and a descent of 6 m and the climb back take the
  // flight stack ~5 s (1.5-3 m/s vertical), so a shorter hold would not even reach the cruise
  // altitude before the next climb.
  double clearance_hold_s = 5.0;
};

// Staggered take-off from the trial's grid (issue #18: up to 100 scouts `spacing_m` = 4 m apart):
// the wave, 0..3, of a scout whose home is `home_xy_m`, from the 2 x 2 checkerboard of grid
// cells (x and y index parity) on a grid of `grid_m`. Scouts of one wave are at least two grid
// steps (8 m, 13 x the x500's 0.62 m collision box) apart; each of a scout's 8 grid neighbours is
// in another wave. The agent starts wave w at w x takeoff_wave_s (sar_brain.cpp): while a scout
// climbs (2 m/s), its neighbours are on the ground or >= 3 m above it, so neither the flight
// stack's take-off transient (a PX4-style take-off drifts < 1 m) nor the 3-D flocking repulsion
// of a neighbour that reached the hold altitude can bring two climbing drones together, and the
// swarm's 100 take-off commands and status changes are spread over 4 steps instead of one. Homes
// off the grid only make the waves less ideal, never unsafe (a vertical climb stays in its column).
int TakeoffWave(const Eigen::Vector2d& home_xy_m, double grid_m);

class ScoutBehaviour {
 public:
  enum class Stage {
    kOnGround, kTakingOff, kAwaitingSector, kSearching, kSwept, kOrbiting, kReturning, kLanding,
    kLanded, kRevisiting,
  };
  static std::string_view StageName(Stage stage);

  explicit ScoutBehaviour(ScoutConfig config);

  // One mission tick. `out` is cleared first (its vectors keep their capacity).
  void Step(const MissionInput& in, MissionOutput* out);

  Stage stage() const { return stage_; }
  const std::vector<Waypoint>& lanes() const { return lanes_; }
  std::size_t lane_index() const { return lane_index_; }
  const ScoutConfig& config() const { return config_; }

 private:
  void Decide(const MissionInput& in, MissionOutput* out);    // stage changes from the mission
  // On a mission stage: revisit, orbit, search, or wait (revisit: the task, or nullptr).
  void DecideMissionStage(const MissionInput& in, const raft::Candidate* revisit, MissionOutput* out);
  void StartSector(const raft::Sector& sector, const MissionInput& in, MissionOutput* out);
  void RunStage(const MissionInput& in, MissionOutput* out);  // the stage's setpoint
  // The setpoints of the longer stages (RunRevisit below is the fourth).
  void RunSearch(const MissionInput& in, MissionOutput* out);
  void RunOrbit(const MissionInput& in, MissionOutput* out);
  void RunReturn(const MissionInput& in, MissionOutput* out);
  void RunTakeoff(const MissionInput& in, MissionOutput* out);
  void RunLanding(const MissionInput& in, MissionOutput* out);
  // Flocks toward `xy_m` at search altitude (waiting for a sector, or over the swept one).
  void FlockOver(const Eigen::Vector2d& xy_m, const MissionInput& in, MissionOutput* out) const;
  void ReportSightings(const MissionInput& in, MissionOutput* out);
  void RetrySightings(const MissionInput& in, MissionOutput* out);
  void Propose(const MissionInput& in, const GroundDetection& d, int tries, MissionOutput* out);
  // The pending candidate the committed state sends this drone to, or nullptr.
  const raft::Candidate* RevisitTask(const raft::MissionState& m) const;
  void RunRevisit(const MissionInput& in, MissionOutput* out);
  void ProposeMiss(const MissionInput& in, MissionOutput* out);
  void PlanSector(const raft::Sector& sector, const Eigen::Vector3d& position_m);
  // This drone's first committed sector it has not swept yet, or nullptr.
  const raft::Sector* NextSector(const raft::MissionState& m) const;
  const raft::Victim* OrbitTarget(const MissionInput& in) const;
  void Enter(Stage stage, const MissionInput& in, MissionOutput* out);
  // Safe height: whether this step commands a cruise altitude, the raise from its obstacle report
  // (once a step, before the stages run), and a cruise altitude raised to the safe height.
  bool Cruising(const MissionInput& in) const;
  void UpdateClearance(const MissionInput& in, MissionOutput* out);
  double Raised(double cruise_z_m) const { return std::max(cruise_z_m, clearance_floor_z_m_); }
  bool ClearanceRaised() const { return clearance_floor_z_m_ > -std::numeric_limits<double>::infinity(); }
  double Altitude() const { return config_.home_m.z() + config_.search_altitude_m; }
  // Where a revisit looks from: the close look's altitude, or the search altitude.
  double LookAltitude() const {
    return config_.revisit_look_altitude_m > 0 ? config_.home_m.z() + config_.revisit_look_altitude_m
                                               : Altitude();
  }

  ScoutConfig config_;
  CameraFootprint footprint_;
  Stage stage_ = Stage::kOnGround;
  raft::Sector planned_sector_;
  bool has_plan_ = false;
  std::vector<raft::Sector> swept_;  // sectors this drone finished (a repeated hand-over is a no-op)
  std::vector<Waypoint> lanes_;
  std::size_t lane_index_ = 0;
  // Where the sweep left its lane (Enter): searching flies back here before going on.
  std::optional<Eigen::Vector2d> rejoin_m_;
  std::uint32_t orbit_victim_ = 0;
  double orbit_reached_s_ = -1.0;
  std::vector<Waypoint> orbit_;
  std::set<std::uint32_t> handled_;  // victims orbited for orbit_time_s (no lifter)
  bool battery_low_reported_ = false;
  std::uint64_t next_seq_ = 1;
  struct RecentReport {
    Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
    Eigen::Vector3d viewer_m = Eigen::Vector3d::Zero();
    double t_s = -1e9;
  };
  std::array<RecentReport, 16> recent_{};
  std::size_t recent_next_ = 0;
  struct Outstanding {  // a report not seen in the committed state yet
    std::uint64_t seq = 0;
    GroundDetection detection;
    double sent_s = 0.0;
    int tries = 0;
  };
  std::vector<Outstanding> outstanding_;  // at most recent_.size()
  // The revisit under way (candidate id 0: none).
  std::uint32_t revisit_id_ = 0;
  double look_start_s_ = -1.0;  // when the candidate came under the camera [s]
  bool revisit_seen_ = false;   // a detection there during this revisit (reported as a sighting)
  double miss_sent_s_ = -1.0;   // the miss proposed (latest try) [s]
  int miss_tries_ = 0;
  // Safe height: the raised cruise altitude (world z; -infinity: not raised), when a report last
  // asked for a raise, and the altitude last logged (event=clearance_climb).
  double clearance_floor_z_m_ = -std::numeric_limits<double>::infinity();
  double clearance_asked_s_ = 0.0;
  double clearance_logged_z_m_ = 0.0;
};

}  // namespace swarmbox::swarm
