// What the agent flies: the built-in plan (--mission plan, the default) or the SAR mission
// (--mission sar), and the mission's inputs from the command line, validated before anything
// joins the bus (bad input: kInvalidArgument, the agent exits 2).
//
//   MissionOptions m;  m.kind = MissionKind::kSar;  m.world_path = "trials/worlds/open_field.yaml";
//   if (Status s = ValidateMissionOptions(m, has_members, plan_given); !s) { print; exit(2); }
//   Result<WorldView> w = LoadWorldView(m.world_path);   // geofence and home only
//
// The agent reads from the world file only what a drone would be told before a mission (the
// search area and the map origin), never the victims: they are found through the camera.
#pragma once

#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"

namespace swarmbox::agent {

enum class MissionKind { kPlan, kSar };
std::string_view MissionKindName(MissionKind kind);  // "plan", "sar"
// "plan" | "sar"; kInvalidArgument naming the accepted values otherwise.
Result<MissionKind> ParseMissionKind(std::string_view text);

struct MissionOptions {
  MissionKind kind = MissionKind::kPlan;
  std::string world_path;         // --world: needed by sar
  std::string payload;            // --payload: a payload of this airframe lies under the drone
  int inference_latency_ms = 40;  // --inference-latency-ms: simulated perception latency [ms]
  // --mission-tuning: SarBrain's tuning numbers as a JSON object, e.g. {"scout_altitude_m": 12}
  // (the trial's mission.tuning; keys and values checked by ParseMissionTuning, sar_brain.hpp).
  std::string tuning_json;
};

inline constexpr int kMaxInferenceLatencyMs = 10000;

// Checks the combination: sar needs `has_members` (Raft) and a world path; plan takes neither a
// world nor a payload nor a tuning; sar takes no plan (`plan_given`: --plan was on the command line); the
// latency lies in [0, kMaxInferenceLatencyMs].
Status ValidateMissionOptions(const MissionOptions& options, bool has_members, bool plan_given);

// The Raft election timeout this drone uses [ms]. The SAR lifter (sar with a payload) waits
// twice the configured one: Raft has no leader priority, and the lifter is the one drone the
// rescue cannot do without, so a fault on "the leader" (or the leader's own failure) should not
// also take the rescue away. Timeouts are drawn from [T, 2T): with 2T the lifter stands for
// election only when no scout has within its own timeout (all scouts gone or cut off), and then
// still can. Every other drone: the configured timeout.
int ElectionTimeoutMsFor(const MissionOptions& options, int configured_ms);

// The agent's view of a world file (trials/worlds/*.yaml): the geofence (the world spans
// |x| <= size_x_m/2, |y| <= size_y_m/2 around the origin, ENU [m]) and the WGS84 home of the
// origin. Other keys are not looked at (victims stay unknown to the agent).
struct WorldView {
  std::string name;
  double size_x_m = 200.0;  // the physics server's defaults when the key is absent
  double size_y_m = 200.0;
  bool has_home = false;
  double home_lat_deg = 0.0, home_lon_deg = 0.0, home_alt_m = 0.0;
};

// Errors: kNotFound (no such file), kInvalidArgument with file:line:col for bad values.
Result<WorldView> LoadWorldView(const std::string& path);

}  // namespace swarmbox::agent
