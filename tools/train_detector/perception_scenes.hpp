// Seeded perception scenes rendered by the physics server's camera (swarmbox::physics::World::
// RenderCamera, the same GroundRenderer the SITL server publishes), with ground truth: what the
// detector is trained on (tools/train_detector) and evaluated on (the perception tests and
// `swarmbox-bench perception`, scoring in tests/agent/swarm/perception_score.hpp), from disjoint
// seeds (kEvaluationSeeds below; the trainer refuses them).
//
// A scene set is made of worlds (200 x 200 m, seeded ground texture, 8 victims at random headings,
// 12 obstacle boxes 1-8 m tall as clutter, kept 2 m clear of the victims) and, per world, camera
// drones at random altitudes, positions (mostly near a victim, offset up to one half footprint width,
// so that victims are often cut by the image border) and yaws, with a per-scene pixel noise.
// Victims are classified per scene: kFull (the whole figure inside the image and not hidden by an
// obstacle: must be detected), kPartial (cut by the border or partly hidden: "don't care", a
// detection of it is neither a true nor a false positive), kAbsent; and by visible_fraction (the
// share of the figure's outline samples inside the image with a clear line of sight), which the
// detection curves use ("at least half visible" must be detected).
//
// The look (SceneSetParams::varied_look, the world schema of #19): each world gets a terrain kind
// and water, a time of day and overcast; each person a pose (lying most often), clothing from a
// palette of greens, browns, greys, dark and bright colours (one in six keeps the hi-vis figure)
// and, for occluded_fraction of them, cover 0.2-0.8 (rubble or vegetation); `distractors` of
// random kinds (tarps, cones, backpacks, debris, rocks) lie 2-9 m from each person. Without
// varied_look the worlds are the original hi-vis look, and occlusion is a low slab (0.3-0.6 m
// rubble) over part of the figure, distractors small low boxes.
// visible_fraction comes from the renderer's own truth (GroundRenderer's VisiblePerson).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "swarmbox/common/result.hpp"
#include "swarmbox/physics/camera_image.hpp"
#include "swarmbox/physics/thermal_renderer.hpp"
#include "swarmbox/physics/world_config.hpp"
#include "swarmbox/swarm/geolocation.hpp"
#include "swarmbox/swarm/thermal_evidence.hpp"
#include "swarmbox/worlds/generator.hpp"

namespace swarmbox::perception_scenes {

using swarm::OpticalPose;
using swarm::PinholeIntrinsics;

enum class Visibility { kFull, kPartial, kAbsent };

struct SceneVictim {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();  // world ENU [m]
  Visibility visibility = Visibility::kAbsent;
  double visible_fraction = 0.0;  // [0, 1]
};

struct Scene {
  physics::CameraImage image;
  PinholeIntrinsics intrinsics;
  OpticalPose true_pose;      // the optical pose the image was rendered from
  double altitude_m = 0.0;    // camera height above the ground [m]
  double noise_std = 0.0;     // pixel noise of this scene [8-bit levels]
  double tilt_rad = 0.0;      // angle between the optical axis and straight down
  std::vector<SceneVictim> victims;
  // With SceneSetParams::thermal: the thermal camera's frame taken with it (the x500's `thermal:`).
  std::optional<physics::ThermalImage> thermal;
};

// The colours generated worlds give tarps and backpacks (orchestrator/worlds generator.cpp
// DistractorLook; tests/orchestrator/worlds checks that every one it writes is here): the varied
// look draws from the same, so the detector is trained on what the mission meets. When the scenes
// had only red backpacks, the CNN took orange ones ([30, 120, 240]) for people at 0.77-0.95 and
// the mission confirmed two (rubble20-a-r1, 2026-11-27).
inline constexpr physics::Bgr kTarpColours[] = {{20, 90, 230}, {30, 30, 200}, {170, 90, 30}, {50, 110, 60}};
inline constexpr physics::Bgr kBackpackColours[] = {{40, 40, 200}, {30, 120, 240}, {60, 80, 70}, {120, 60, 30}};

// Which distractor kinds a varied-look world gets (perception_scenes.cpp AddDistractors).
enum class DistractorMix {
  kAllKinds,     // tarps, cones, backpacks, debris and rocks, equally often
  kConesRubble,  // rubble terrain in every world and only traffic cones: the shipped blob model's
                 // false alarms at 30 m (a cone and its shadow, rubble clumps), for hard negatives
};

struct SceneSetParams {
  std::uint64_t seed = 1;
  int scenes = 240;
  int scenes_per_world = 24;
  double min_altitude_m = 10.0;
  double max_altitude_m = 40.0;
  double min_noise_std = 2.0;
  double max_noise_std = 10.0;
  double near_victim_fraction = 0.75;  // share of views centred near a victim
  double near_victim_offset = 1.2;     // view centre up to this * half the footprint width away
  // Of the views not near a person, the share centred near a distractor likewise (the look-alikes
  // a revisit's close look meets: swarmbox-fit-thermal).
  double near_distractor_fraction = 0.0;
  double occluded_fraction = 0.0;      // share of victims partly covered by a low slab
  int distractors = 0;                 // distractors near each victim
  bool varied_look = false;            // terrain, light, poses, clothing, cover, distractor kinds
  DistractorMix distractor_mix = DistractorMix::kAllKinds;  // with varied_look only
  // Set: the worlds are generated search areas (orchestrator/worlds GenerateWorld, as a trial's
  // `world: {generate: ...}` makes them; the spec's seed is ignored, each world's is drawn from
  // `seed`), with their own terrain, light, people, cover, obstacles and distractors:
  // occluded_fraction, distractors, varied_look and distractor_mix are not used. The views are
  // placed as above (near_victim_fraction of them near a person).
  std::optional<worlds::GenerateSpec> generated{};
  // The x500's thermal camera too (Scene::thermal; nadir views only): what `swarmbox-bench
  // perception --thermal 1` scores the colour detector with its thermal evidence on.
  bool thermal = false;
};

// The mission's search area (trials/sar_rubble.yaml's world: a 160 x 160 m rubble field, 4
// people, 30 slabs and walls, 25 distractors): what the trainer's world sets and the bench's
// world case generate.
worlds::GenerateSpec SarRubbleSpec();

// Scene-set seeds the perception tests and the bench evaluate on by default: never trained on.
inline constexpr std::uint64_t kEvaluationSeeds[] = {20261121, 30, 40, 77, 78, 1, 2, 3, 4, 5};

// Renders the scene set. Fails (kNotFound...) when the x500 airframe file cannot be read.
Result<std::vector<Scene>> RenderScenes(const SceneSetParams& params);

// A scene's thermal frame as the agent's perception takes it (swarm::ThermalView: kelvin, the
// thermal camera's intrinsics and its true optical pose).
swarm::ThermalView ThermalViewOf(const physics::ThermalImage& image);

// One nadir view of `world` from a camera drone hovering at altitude_m over centre_m with the
// given yaw and pixel noise (unit tests place a victim or draw a distractor and look).
Result<Scene> RenderView(const physics::WorldConfig& world, const Eigen::Vector2d& centre_m, double altitude_m,
                         double yaw_rad, double noise_std);

// Tilted views: the camera drones are spawned hovering (rotors at hover speed) and given a random
// differential rotor command (+-differential on throttle, by rotor position) for burst_s of
// simulated flight, which rolls and pitches them before the frame is rendered: the physics
// server's own attitude and camera mounting, not a pose made up here.
Result<std::vector<Scene>> RenderTiltedScenes(const SceneSetParams& params, double differential,
                                              double burst_s);

// Thermal patches for the thermal classifier (swarmbox-fit-thermal --thermal-views): nadir frames
// of the x500's thermal camera (physics::ThermalRenderer, airframe `thermal:`) over generated rubble
// fields (SarRubbleSpec, a new world every views_per_world frames, its seed drawn from `seed`), from
// min_altitude_m to max_altitude_m at a random yaw, each centred within 4 m of a person (40 % of
// the views), of a distractor (30 %), beside an obstacle (20 %) or anywhere (10 %). In each frame the patch
// (swarm::ThermalPatchAt) at each person at least half visible (a positive; placed off the person
// by a geolocation error of geolocation_sigma_m per axis), at each distractor, and at two ground
// points, one beside an obstacle (negatives); patches leaving the frame are skipped. Many more
// people and look-alikes, in more surroundings, than the colour detector's candidates hold.
struct ThermalPatchParams {
  std::uint64_t seed = 1;
  int views = 4000;
  int views_per_world = 40;
  double min_altitude_m = 16.0, max_altitude_m = 32.0;
  double geolocation_sigma_m = 0.4;
};
struct ThermalPatch {
  std::vector<float> patch;  // kThermalPatchPx squared, ThermalPatchAt's
  bool person = false;
  int world = 0;  // the index of its world in the set
};
Result<std::vector<ThermalPatch>> RenderThermalPatches(const ThermalPatchParams& params);

// A flown trial's camera frames, rendered again (`swarmbox-bench perception --replay RUN`): the
// trial folder's world.yaml and truth.csv (every drone's pose and body rates over simulated time)
// give each camera drone's frames as its camera took them in flight, through the same
// GroundRenderer, with the renderer's truth: the detector's figures on the mission's own frames
// (its altitudes, speeds, tilts, motion blur, light and ground), which tells a victim the mission
// never saw from one it saw and failed to confirm. The camera is the x500's (the scouts' airframe,
// trials/airframes/x500.yaml). A frame is taken each time the drone has moved its
// trigger_distance_m horizontally since the last (or 1 / rate_hz s of
// truth without trigger_distance_m), while it is between min_height_m and max_height_m above the
// ground; truth.csv is read by report::ReadTruthCsv, its rows the physics server's (50 a second
// per drone: 0.14 m apart at 7 m/s), so a frame lands within one row of where the trigger fired.
// The pixel noise is seeded per frame, not the server's.
struct ReplayParams {
  std::string trial_dir;               // holds world.yaml and truth.csv
  std::string drone_prefix = "scout";  // which drones carry the camera (name prefix)
  double min_height_m = 10.0;
  double max_height_m = 60.0;
  bool thermal = false;  // each frame's thermal one too (Scene::thermal; the x500's `thermal:`)
};
struct ReplayFrame {
  std::string drone;
  double t_s = 0.0;
  Scene scene;
};
// Calls on_frame for each frame in truth.csv's order (frames are not kept: a 15-minute mission is
// thousands). kNotFound without world.yaml or truth.csv; kInvalidArgument for a truth.csv without
// its columns or with a short row.
Status ReplayTrial(const ReplayParams& params,
                   const std::function<void(const physics::WorldConfig&, const ReplayFrame&)>& on_frame);

}  // namespace swarmbox::perception_scenes
