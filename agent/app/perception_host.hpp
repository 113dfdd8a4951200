// PerceptionHost: the agent's perception, beside the brain (a scout's camera): camera frames plus
// the flight stack's estimate history and the simulated inference latency -> geolocated victim
// detections as brain::Detection (Input::detections of the brain; the node also broadcasts them
// on the radio as bus::Detection). No bus here: AgentNode converts the images at its edge, so
// perception is tested without DDS (tests/agent/app/perception_host_test.cpp).
//
//   auto p = PerceptionHost::Create({.camera = airframe.camera, .inference_latency_s = 0.04});
//   p->RecordEstimate(t_s, est);                       // every control step (capture-time lookup)
//   p->OnDepthFrame(f.frame, f.camera_pose, f.intrinsics);  // each newly released depth frame
//   p->OnThermalFrame(kelvin, k, capture_t_s);         // a thermal frame, before its colour frame
//   p->OnCameraFrame(bgr, k, capture_t_s);             // each camera image of this step
//   p->PopVisible(t_s, &detections);                   // capture + latency <= t_s: to the brain
//
// Geolocation uses the *estimated* pose of the capture step (the nearest estimate within 20 ms;
// frames older than the history, ~0.5 s, are dropped), and only steady frames: a frame taken
// more tilted than max_tilt_rad or turning faster than max_rate_rad_s is skipped (attitude errors
// multiply on the ground). Time is simulated seconds, frames world ENU [m]. Not thread-safe.
//
// With a thermal camera (airframe `thermal:`; PerceptionConfig::thermal enabled), the thermal frame
// taken with a colour frame (the same capture time; it arrives first) is the colour detector's
// second opinion: each candidate's confidence takes the thermal evidence at its ground point
// (swarm::ThermalEvidence, the shipped fit), seen from the same estimated pose through the thermal
// camera's own offset and intrinsics (swarm::VictimPerception::ProcessFrame).
//
// Where the drone's stereo camera saw the ground (issue #23), detections are placed on the surface
// it saw, not on the flat plane z = 0 (swarm::PixelToSurface): the newest depth frame (DepthHost's,
// the left camera's pose from the estimate at its exposure) is kept, and a depth::DepthSurface is
// built from it only when a camera frame needs it, and only if the depth was captured within
// depth_max_age_s of the camera frame (the drone moves 1.25 m in 0.25 s at 5 m/s, but the surface
// is in world coordinates: what matters is that the scene has not changed, and that the frame saw
// the same ground); it is built on the first detection to geolocate, not for frames without one
// (8-16 ms for a frame with depth). The heights are the median of the cells within depth_height_radius_m of
// where the ray lands. The depth reaches 15 m (DepthSurfaceConfig::max_range_m): a scout at its
// 30 m search altitude has none, and geolocates on the flat plane as before.

#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/airframe/airframe.hpp"
#include "swarmbox/brain/brain.hpp"
#include "swarmbox/bus/messages.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/depth/depth_camera.hpp"
#include "swarmbox/depth/ground_plane.hpp"
#include "swarmbox/flight/estimator.hpp"
#include "swarmbox/swarm/geolocation.hpp"
#include "swarmbox/swarm/victim_perception.hpp"

namespace swarmbox::agent {

struct PerceptionConfig {
  airframe::CameraSpec camera;                 // the airframe's (offset_m: where the frames are taken from)
  airframe::ThermalSpec thermal;               // the airframe's; disabled: thermal frames are not used
  swarm::ThermalEvidence thermal_evidence = swarm::ShippedThermalEvidence();
  double inference_latency_s = 0.040;          // simulated detector latency [s], >= 0
  double max_tilt_rad = 0.2;                   // frames taken more tilted are not used
  double max_rate_rad_s = 0.5;                 // nor while turning faster
  // A depth frame's heights are used for camera frames captured within this of its exposure [s]
  // (the depth arrives 30-50 ms after its exposure, a frame every few control steps).
  double depth_max_age_s = 0.25;
  // The surface's height where a ray lands: the median of the depth's cells (0.25 m) within this
  // [m]: a person lying down (~1.7 x 0.5 m) and the surface they lie on.
  double depth_height_radius_m = 0.5;
};

class DepthHeights;

class PerceptionHost {
 public:
  // kInvalidArgument: a negative latency or depth_max_age_s, a depth_height_radius_m <= 0.
  static Result<std::unique_ptr<PerceptionHost>> Create(const PerceptionConfig& config);
  ~PerceptionHost();

  void RecordEstimate(double t_s, const flight::StateEstimate& est);
  // Detects and geolocates; the detections wait out the latency. Frames without an estimate of
  // their capture step, tilted or turning are skipped.
  // With a depth frame captured within depth_max_age_s, on the surface it saw (see above).
  void OnCameraFrame(const cv::Mat& bgr, const swarm::PinholeIntrinsics& k, double capture_t_s);
  // A thermal frame (CV_32F kelvin; copied), for the colour frame of the same capture time.
  // Ignored without a thermal camera in the config.
  void OnThermalFrame(const cv::Mat& kelvin, const swarm::PinholeIntrinsics& k, double capture_t_s);
  // The newest depth frame (its depth_m is shared, not copied: DepthCamera makes each frame's
  // anew); `camera_pose`: its left camera's optical frame at the exposure (LeftCameraPose).
  void OnDepthFrame(const depth::DepthFrame& frame, const bus::Pose& camera_pose,
                    const depth::CameraIntrinsics& intrinsics);
  // Appends the detections visible at t_s (capture + latency <= t_s), label "victim".
  void PopVisible(double t_s, std::vector<brain::Detection>* out);

 private:
  explicit PerceptionHost(const PerceptionConfig& config);

  struct Estimate {
    double t_s = -1.0;
    flight::Vec3 pos_m = flight::Vec3::Zero();
    flight::Quat att = flight::Quat::Identity();
    flight::Vec3 rate_rad_s = flight::Vec3::Zero();
  };

  // The newest depth frame's heights for a camera frame captured at capture_t_s, or nullptr: no
  // depth frame, or none captured near enough.
  const swarm::GroundHeightSource* SurfaceFor(double capture_t_s) const;

  PerceptionConfig config_;
  swarm::VictimPerception perception_;
  // The newest depth frame; its depth::DepthSurface is built on the first height asked of it (a
  // detection to geolocate), not per camera frame (perception_host.cpp).
  std::unique_ptr<const DepthHeights> depth_;
  std::vector<Estimate> history_;  // ring, one entry per control step
  std::size_t history_next_ = 0;
  std::vector<swarm::GroundDetection> visible_;
  cv::Mat thermal_kelvin_;  // the newest thermal frame
  swarm::PinholeIntrinsics thermal_k_;
  double thermal_t_s_ = -1.0;  // its capture time; < 0: none
};

}  // namespace swarmbox::agent
