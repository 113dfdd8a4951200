// MissionSim: a pure closed-loop test rig for the SAR mission behaviours. Kinematic drones follow
// the behaviours' setpoint requests (kFlock through swarm::Flocking), a raft::MissionState stands
// in for the committed log (every proposal is applied in order `commit_delay_s` after it was
// made, which is what Raft gives when nothing fails), a fake camera turns victims inside a scout's
// footprint into detections, and a fake world carries out payload attach/release with the
// physics server's sling geometry (hook within sling_length +- tolerance of the stretcher).
// Not a physics test: it checks that the behaviours, the leader planner and MissionState fit.
//
// Failures: a drone can be killed (its behaviour stops, it drops to the ground, it is never heard
// again) or fall silent for a while (it flies on, but nobody hears its state and its proposals
// are lost: a radio cut). Every drone runs a LeaderPlanner (Track on each step); the leader is
// the first drone in the list that is alive and heard, so killing it hands the lead to the next.
// Each drone's state is heard by the others state_age_s after it was taken.
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "swarmbox/swarm/flocking.hpp"
#include "swarmbox/swarm/leader_planner.hpp"
#include "swarmbox/swarm/lifter_sequence.hpp"
#include "swarmbox/swarm/scout_behaviour.hpp"

namespace swarmbox::swarm::testing {

struct SimDrone {
  std::string name;
  Role role = Role::kScout;
  Vec3 home_m = Vec3::Zero();
  double base_height_m = 0.23;
};

struct MissionSimConfig {
  std::uint64_t seed = 1;
  double dt_s = 0.05;
  double commit_delay_s = 0.3;
  Rect area{-100, -60, 100, 60};
  Vec2 geofence_m{400, 400};  // the flocking geofence, centred [m]
  // Scouts as SarBrain tunes them (keep searching during a rescue, home when swept, descend to
  // 5 m before landing, orbit 20 s) instead of ScoutConfig's defaults.
  bool agent_tuning = false;
  double takeoff_wave_s = 0.0;  // > 0: staggered take-off, TakeoffWave(home, 4 m) waves apart [s]
  std::vector<SimDrone> drones;
  std::vector<Vec2> victims_m;
  double detection_sigma_m = 0.5;  // fake camera geolocation noise [m]
  double victim_confidence = 0.95;  // of every detection of a victim
  // Chance that a frame with a victim in the footprint detects it (seeded): < 1 makes misses.
  double recall = 1.0;
  // False alarms: places where the fake camera reports a victim once (the first frame any scout
  // has one in its footprint, at false_alarm_confidence) and never again: a revisit sees nothing.
  std::vector<Vec2> false_alarms_m;
  double false_alarm_confidence = 0.9;
  double loading_time_s = 10.0;
  // The lifter's drop-spot survey (LifterConfig::survey_drop_point) and the fake depth host's
  // answer to want_drop_spot, on the next step: a flat spot at the default point plus
  // drop_spot_offset_m; nullopt: no depth frames (it never answers).
  bool lifter_survey_drop_point = false;
  std::optional<Vec2> drop_spot_offset_m;
  // The scouts' safe height (ScoutConfig::min_clearance_m, MissionInput::obstacle_top_z_m):
  // obstacles (trees, walls) as boxes standing on the ground (z 0), and a fake depth host that
  // gives each scout, at the camera's 5 Hz, the highest top (the ground's or an obstacle's)
  // within fake_depth_radius_m of it horizontally and fake_depth_range_m below it (ClearanceBelow's
  // defaults), nothing when none is within range. Without fake_depth the obstacles are only
  // measured (min_obstacle_clearance_m).
  struct Obstacle {
    Rect area;
    double top_z_m = 0;
  };
  std::vector<Obstacle> obstacles;
  bool fake_depth = false;
  double fake_depth_radius_m = 5.0;
  double fake_depth_range_m = 15.0;
  double scout_altitude_m = 30.0;      // ScoutConfig::search_altitude_m
  double scout_min_clearance_m = 0.0;  // ScoutConfig::min_clearance_m
  // min_obstacle_clearance_m(true) ignores this band inside an obstacle's edges [m] (the climb).
  double obstacle_edge_m = 5.0;
  double battery_fraction_at_start = 1.0;
  double battery_drain_per_s = 0.0;  // fraction per second (crude: tests of battery_low)
  bool scouts_only_report_once = false;
  double state_age_s = 0.2;  // how old a heard state is (5 Hz, radio delay) [s]
  struct Outage {
    std::string drone;
    double from_s = 0;
    double until_s = 1e9;  // killed: never back (ignored); silent: heard again from here
    bool killed = true;
  };
  std::vector<Outage> outages;
};

class MissionSim {
 public:
  explicit MissionSim(MissionSimConfig config);

  void Step();
  // Runs until `until(*this)` or max_s of simulated time; returns whether `until` became true.
  template <typename F>
  bool RunUntil(F until, double max_s) {
    while (t_s_ < max_s) {
      Step();
      if (until(*this)) return true;
    }
    return false;
  }

  double t_s() const { return t_s_; }
  const raft::MissionState& mission() const { return mission_; }
  const std::vector<std::string>& log() const { return log_; }  // every event line, in order
  bool Logged(const std::string& event) const;                   // some line has event=<event>
  std::string_view mode(std::size_t drone) const { return modes_[drone]; }
  const Vec3& position(std::size_t drone) const { return pos_[drone]; }
  const Vec2& stretcher_m() const { return stretcher_xy_; }
  bool stretcher_attached() const { return attached_; }
  double stretcher_mass_kg() const { return payload_mass_kg_; }
  // Closest approach of two airborne drones (> 2 m up), and of two drones both flocking [m].
  double min_pair_distance_m() const { return min_pair_m_; }
  double min_flocking_pair_distance_m() const { return min_flock_pair_m_; }
  // Where the closest approach of two airborne drones happened: "t=.. a(mode) b(mode)".
  const std::string& min_pair_where() const { return min_pair_where_; }
  std::size_t rejected_proposals() const { return rejected_; }
  // The least height of an airborne scout above an obstacle's top while over it (inner: at least
  // obstacle_edge_m inside its edges) [m]; 1e9 if never over one.
  double min_obstacle_clearance_m(bool inner) const {
    return inner ? min_inner_clearance_m_ : min_clearance_m_;
  }
  std::size_t leader() const { return leader_index_; }
  // A failure from now on (e.g. once a drone logged its first sector progress).
  void AddOutage(MissionSimConfig::Outage outage) { config_.outages.push_back(std::move(outage)); }
  // The first logged line with event=<event> (and `also` in it), or "".
  std::string FirstLine(const std::string& event, const std::string& also = "") const;
  // Its t= value, or -1.
  double FirstTime(const std::string& event, const std::string& also = "") const;

 private:
  struct Pending {
    double due_s;
    raft::MissionCommand command;
  };

  MissionSimConfig config_;
  std::mt19937_64 rng_;
  raft::MissionState mission_;
  std::uint64_t index_ = 0;
  std::vector<Pending> pending_;
  std::vector<ScoutBehaviour> scouts_;         // by drone index where role == scout
  std::vector<LifterSequence> lifters_;
  std::vector<int> behaviour_of_;              // index into scouts_ or lifters_
  std::vector<Flocking> flock_;
  bool Killed(std::size_t drone) const;
  bool Silent(std::size_t drone) const;
  std::vector<LeaderPlanner> planners_;        // one per drone (whoever leads uses its own)
  std::size_t leader_index_ = 0;
  std::vector<double> heard_s_;                // when each drone's latest state was taken
  std::vector<std::string> heard_mode_;        // and its mode and position then
  std::vector<Vec2> heard_pos_;
  std::vector<Vec3> pos_, vel_;
  std::vector<double> yaw_;
  std::vector<std::string_view> modes_;
  std::vector<MissionOutput> out_;
  std::vector<std::optional<DropSpotAnswer>> drop_spot_answers_;  // by drone: for its next step
  std::vector<std::vector<GroundDetection>> detections_;
  std::vector<bool> false_alarm_fired_;
  std::vector<NeighbourState> scratch_;
  Vec2 stretcher_xy_ = Vec2::Zero();
  bool attached_ = false;
  double payload_mass_kg_ = 0.0;
  double next_camera_s_ = 0.0;
  double min_pair_m_ = 1e9;
  double min_flock_pair_m_ = 1e9;
  std::string min_pair_where_;
  std::size_t rejected_ = 0;
  double min_clearance_m_ = 1e9;
  double min_inner_clearance_m_ = 1e9;
  std::optional<double> FakeDepth(std::size_t drone) const;  // the fake depth host's top, or none
  void MeasureClearance(std::size_t drone);
  std::vector<std::string> log_;
  double t_s_ = 0.0;
};

}  // namespace swarmbox::swarm::testing
