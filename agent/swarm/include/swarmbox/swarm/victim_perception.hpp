// VictimPerception: the agent's perception pipeline in one object: VictimDetector on each camera
// frame, geolocation of each blob through the pinhole model with the *estimated* camera pose, and
// the simulated inference latency (LatencyQueue). Pure: frames, poses and times in.
//
// How the agent calls it (agent/app, on each bus::CameraImage for this drone):
//
//   cv::Mat bgr(img.height_px, img.width_px, CV_8UC3, img.data.data(), img.row_stride_bytes);
//   const swarm::OpticalPose cam = swarm::OpticalPoseFromBody(est_at_capture.pos_m,
//                                                             est_at_capture.att, camera_offset_m);
//   perception.ProcessFrame(bgr, {k.fx_px, k.fy_px, k.cx_px, k.cy_px}, cam, img.sim_time_ns * 1e-9);
//   // or, with the surface's heights from the drone's depth (a GroundHeightSource; PerceptionHost):
//   perception.ProcessFrame(bgr, k, cam, t_s, &surface);
//   ...                                                       // every control step:
//   ready.clear();
//   perception.PopVisible(now_s, &ready);                    // capture + latency <= now
//   for (const GroundDetection& d : ready) publish bus::Detection{...} and feed MissionInput
//
// ("mono8" frames must be converted to BGR first; "rgb8" swapped: the detector thresholds colour.)
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/swarm/detection.hpp"
#include "swarmbox/swarm/geolocation.hpp"
#include "swarmbox/swarm/latency_queue.hpp"
#include "swarmbox/swarm/thermal_evidence.hpp"
#include "swarmbox/swarm/victim_detector.hpp"

namespace swarmbox::swarm {

struct PerceptionParams {
  VictimDetectorParams detector;
  double latency_s = 0.040;          // simulated inference latency [s]
  std::size_t queue_capacity = 64;
  double ground_z_m = 0.0;           // the ground plane (flat world) [m, ENU z]
  double min_confidence = 0.5;       // blobs below are not reported
  // Uncertainty model for position_sigma_m of each detection.
  double position_sigma_m = 0.5;     // estimated camera position, horizontal 1-sigma [m]
  double attitude_sigma_rad = 0.01;  // estimated attitude 1-sigma [rad]
  double pixel_sigma_px = 0.7;       // blob centroid 1-sigma [px]
  // With a thermal frame (ProcessFrame's `thermal`): each candidate's confidence takes the
  // thermal evidence at its ground point (thermal_evidence.hpp) before min_confidence applies.
  ThermalEvidence thermal;
};

class VictimPerception {
 public:
  explicit VictimPerception(const PerceptionParams& params = {});

  // Detects and geolocates; detections enter the latency queue. Returns how many were queued.
  // Without `surface` each detection is where its pixel's ray meets the plane z = ground_z_m;
  // with one, where it meets the surface's heights (PixelToSurface: a person on a rubble slab seen
  // obliquely is not pushed height x tan(off-nadir angle) beyond it).
  // With `thermal` (a thermal frame taken with this one, its estimated pose), a candidate the
  // thermal camera sees (its contrast defined: ThermalContrastAt) gets the confidence of both
  // (ThermalFusion: the contrast and, with the evidence's classifier, its logit on the patch);
  // one it does not see (the thermal camera's view is narrower) keeps the colour detector's.
  int ProcessFrame(const cv::Mat& bgr, const PinholeIntrinsics& k, const OpticalPose& camera_pose,
                   double capture_time_s, const GroundHeightSource* surface = nullptr,
                   const ThermalView* thermal = nullptr);
  // Appends the detections that are visible at now_s (capture + latency <= now_s).
  void PopVisible(double now_s, std::vector<GroundDetection>* out) { queue_.PopVisible(now_s, out); }

  const LatencyQueue& queue() const { return queue_; }
  const PerceptionParams& params() const { return params_; }

 private:
  PerceptionParams params_;
  VictimDetector detector_;
  ThermalFusion thermal_;
  LatencyQueue queue_;
  std::vector<ImageBlob> blobs_;
};

}  // namespace swarmbox::swarm
