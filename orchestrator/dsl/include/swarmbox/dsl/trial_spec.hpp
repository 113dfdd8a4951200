// TrialSpec: the trial model, what a trial file says (ARCHITECTURE.md "A trial description").
//
// The YAML format and the C++ builder below produce the same value; the runner turns it into a
// component tree (swarmbox::runner::PlanTrial). The builder reads like the file:
//
//   TrialSpec t = TrialSpec::Named("sar-search")
//                     .Seed(42)
//                     .World("worlds/open_field.yaml")
//                     .Drone("scout_1", "x500", {0, 0, 0})
//                     .Drone("lifter", "x8_heavy", {0, -10, 0}, "stretcher")
//                     .Mesh(MeshSpec::Netem(100, 20, 0.05))
//                     .Fault(FaultSpec::Kill(Duration::Seconds(30), "raft_leader"))
//                     .EndOn("event=mission_complete", Outcome::kSuccess)
//                     .EndOn("event=collision", Outcome::kFailure, "collision")
//                     .Timeout(Duration::Minutes(10));
//
// Faults are parsed and validated now and carried out by the fault injector (a later issue).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/dsl/duration.hpp"
#include "swarmbox/dsl/outcome.hpp"

namespace swarmbox::dsl {

enum class Middleware { kCycloneDds, kFastDds };
std::string_view MiddlewareName(Middleware middleware);  // "cyclonedds", "fastdds"

struct DroneSpec {
  std::string name;                 // [a-z][a-z0-9_]*, unique in the trial
  std::string airframe;             // trials/airframes/<airframe>.yaml
  std::array<double, 3> pose{};     // start position [m], world frame (x east, y north, z up)
  std::string payload;              // "" = none
  yaml::Mark mark;                  // where the drone was declared
};

// tc netem semantics for the radio link of every agent (network.mesh).
struct MeshSpec {
  double delay_ms = 0;
  double jitter_ms = 0;
  std::string distribution;  // "" = netem default; normal, pareto, paretonormal
  double loss = 0;           // probability [0, 1]
  double duplicate = 0;      // probability [0, 1]
  double corrupt = 0;        // probability [0, 1]
  double rate_kbit = 0;      // 0 = unlimited
  // delay [ms], jitter [ms], loss probability.
  static MeshSpec Netem(double delay_ms, double jitter_ms = 0, double loss = 0) {
    MeshSpec m;
    m.delay_ms = delay_ms;
    m.jitter_ms = jitter_ms;
    m.loss = loss;
    return m;
  }
  bool impaired() const {
    return delay_ms > 0 || jitter_ms > 0 || loss > 0 || duplicate > 0 || corrupt > 0 ||
           rate_kbit > 0;
  }
};

enum class FaultKind { kKill, kStop, kPause, kRestart, kPartition, kGpsDropout, kWindGust, kNetem };
// The YAML key of each kind: "kill", "stop", "pause", "restart", "partition", "gps_dropout",
// "wind_gust", "netem".
std::string_view FaultKindName(FaultKind kind);

// One scheduled fault, `at` simulated time after the start. Shapes (YAML):
//   {at: 30s, kill: raft_leader}               kill|stop|pause|restart: a drone, physics or raft_leader
//   {at: 40s, pause: scout_2, for: 10s}        stop/pause may last `for`
//   {at: 40s, partition: [[scout_1, scout_2], [scout_3, lifter]], for: 20s}
//   {at: 10s, gps_dropout: scout_1, for: 5s}
//   {at: 50s, wind_gust: {speed_mps: 8, direction_deg: 90}, for: 3s}
//   {at: 20s, netem: {delay_ms: 300, loss: 0.2}, on: [scout_1], for: 30s}   on: default every drone
struct FaultSpec {
  Duration at;
  FaultKind kind = FaultKind::kKill;
  std::vector<std::string> targets;              // kill..restart, gps_dropout, netem `on`
  std::vector<std::vector<std::string>> groups;  // partition
  Duration duration;                             // `for`; zero = until the end
  MeshSpec netem;
  double wind_speed_mps = 0;
  double wind_direction_deg = 0;  // where the wind blows to, clockwise from north
  yaml::Mark mark;

  static FaultSpec Kill(Duration at, std::string target);
};

struct EndSpec {
  std::string on;                      // regex on a log line (see dsl::EndCondition)
  Outcome outcome = Outcome::kSuccess;
  std::string reason;                  // "" = the pattern
  std::string from;                    // a component ("physics", a drone); "" = any
};

struct TimeoutSpec {
  Duration sim;                         // simulated time; zero = none
  Duration wall;                        // wall-clock guard; zero = derived from sim and rtf
  Outcome outcome = Outcome::kTimeout;  // what running out of simulated time means
};

struct TrialSpec {
  std::string name;  // [a-z0-9][a-z0-9_.-]*, at most 40 characters; used in folder/Docker names
  std::uint64_t seed = 0;
  Middleware middleware = Middleware::kCycloneDds;
  std::string world;  // relative to the trials directory
  double rtf = 1.0;   // real-time factor, 0 = as fast as possible
  std::vector<DroneSpec> drones;
  MeshSpec mesh;
  std::vector<FaultSpec> faults;
  std::vector<EndSpec> end;
  TimeoutSpec timeout;

  std::string trials_dir;  // where world and airframe references resolve ("" = not checked)
  yaml::Node document;     // the resolved description (after --set), written as trial.yaml

  // --- the C++ builder ---
  static TrialSpec Named(std::string name);
  TrialSpec& Seed(std::uint64_t seed);
  TrialSpec& Using(Middleware middleware);
  TrialSpec& World(std::string world);
  TrialSpec& Rtf(double rtf);
  TrialSpec& Drone(std::string name, std::string airframe, std::array<double, 3> pose,
                   std::string payload = {});
  TrialSpec& Mesh(MeshSpec mesh);
  TrialSpec& Fault(FaultSpec fault);
  TrialSpec& EndOn(std::string pattern, Outcome outcome, std::string reason = {},
                   std::string from = {});
  TrialSpec& Timeout(Duration sim, Outcome outcome = Outcome::kTimeout, Duration wall = {});

  const DroneSpec* FindDrone(std::string_view drone_name) const;
};

// The YAML document of a spec (what LoadTrial would read back to an equal spec).
yaml::Node ToDocument(const TrialSpec& spec);

}  // namespace swarmbox::dsl
