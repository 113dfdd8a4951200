// Seeded perception scenes rendered by the physics server's camera (swarmbox::physics::World::
// RenderCamera, the same GroundRenderer the SITL server publishes), with ground truth, and the
// scoring used by the perception tests and `swarmbox-bench perception`.
//
// A scene set is made of worlds (200 x 200 m, seeded ground texture, 8 victims at random headings,
// 12 obstacle boxes 1-8 m tall as clutter, kept 2 m clear of the victims) and, per world, camera
// drones at random altitudes, positions (mostly near a victim, offset up to one half footprint width,
// so that victims are often cut by the image border) and yaws, with a per-scene pixel noise.
// Victims are classified per scene: kFull (the whole figure inside the image and not hidden by an
// obstacle: must be detected), kPartial (cut by the border or partly hidden: "don't care", a
// detection of it is neither a true nor a false positive), kAbsent.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "swarmbox/common/result.hpp"
#include "swarmbox/physics/camera_image.hpp"
#include "swarmbox/swarm/geolocation.hpp"
#include "swarmbox/swarm/victim_perception.hpp"

namespace swarmbox::swarm::testing {

enum class Visibility { kFull, kPartial, kAbsent };

struct SceneVictim {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();  // world ENU [m]
  Visibility visibility = Visibility::kAbsent;
};

struct Scene {
  physics::CameraImage image;
  PinholeIntrinsics intrinsics;
  OpticalPose true_pose;      // the optical pose the image was rendered from
  double altitude_m = 0.0;    // camera height above the ground [m]
  double noise_std = 0.0;     // pixel noise of this scene [8-bit levels]
  double tilt_rad = 0.0;      // angle between the optical axis and straight down
  std::vector<SceneVictim> victims;
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
};

// Renders the scene set. Fails (kNotFound...) when the x500 airframe file cannot be read.
Result<std::vector<Scene>> RenderScenes(const SceneSetParams& params);

// Tilted views: the camera drones are spawned hovering (rotors at hover speed) and given a random
// differential rotor command (+-differential on throttle, by rotor position) for burst_s of
// simulated flight, which rolls and pitches them before the frame is rendered: the physics
// server's own attitude and camera mounting, not a pose made up here.
Result<std::vector<Scene>> RenderTiltedScenes(const SceneSetParams& params, double differential,
                                              double burst_s);

struct PerceptionScore {
  int scenes = 0;
  int full_victims = 0;        // must-detect instances
  int true_positives = 0;      // detections matched to a kFull victim (one per victim)
  int false_positives = 0;     // detections matching no victim in view
  int partial_detected = 0;    // detections matched to a kPartial victim (not scored)
  int partial_victims = 0;
  std::vector<double> errors_m;  // geolocation error of each true positive [m]
  double precision() const;
  double recall() const;
  double median_error_m() const;
  double p90_error_m() const;
};

// Runs the pipeline on every scene with the camera pose `perturb`ed (seeded: position 1-sigma
// position_sigma_m per axis, attitude 1-sigma attitude_sigma_rad per axis; zero = true pose) and
// scores it: a detection matches the nearest victim within match_radius_m (victims lie >= 6 m
// apart, so 2.5 m cannot match the wrong one; MissionState merges sightings within 5 m).
struct PoseNoise {
  std::uint64_t seed = 7;
  double position_sigma_m = 0.0;
  double attitude_sigma_rad = 0.0;
};
PerceptionScore ScorePerception(const std::vector<Scene>& scenes, const PerceptionParams& params,
                                const PoseNoise& pose_noise, double match_radius_m = 2.5);

}  // namespace swarmbox::swarm::testing
