// PerceptionHost: the agent's perception, beside the brain (a scout's camera): camera frames plus
// the flight stack's estimate history and the simulated inference latency -> geolocated victim
// detections as brain::Detection (Input::detections of the brain; the node also broadcasts them
// on the radio as bus::Detection). No bus here: AgentNode converts the images at its edge, so
// perception is tested without DDS (tests/agent/app/perception_host_test.cpp).
//
//   auto p = PerceptionHost::Create({.camera = airframe.camera, .inference_latency_s = 0.04});
//   p->RecordEstimate(t_s, est);                       // every control step (capture-time lookup)
//   p->OnCameraFrame(bgr, k, capture_t_s);             // each camera image of this step
//   p->PopVisible(t_s, &detections);                   // capture + latency <= t_s: to the brain
//
// Geolocation uses the *estimated* pose of the capture step (the nearest estimate within 20 ms;
// frames older than the history, ~0.5 s, are dropped), and only steady frames: a frame taken
// more tilted than max_tilt_rad or turning faster than max_rate_rad_s is skipped (attitude errors
// multiply on the ground). Time is simulated seconds, frames world ENU [m]. Not thread-safe.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/airframe/airframe.hpp"
#include "swarmbox/brain/brain.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/flight/estimator.hpp"
#include "swarmbox/swarm/geolocation.hpp"
#include "swarmbox/swarm/victim_perception.hpp"

namespace swarmbox::agent {

struct PerceptionConfig {
  airframe::CameraSpec camera;                 // the airframe's (offset_m: where the frames are taken from)
  double inference_latency_s = 0.040;          // simulated detector latency [s], >= 0
  double max_tilt_rad = 0.2;                   // frames taken more tilted are not used
  double max_rate_rad_s = 0.5;                 // nor while turning faster
};

class PerceptionHost {
 public:
  // kInvalidArgument: a negative latency.
  static Result<std::unique_ptr<PerceptionHost>> Create(const PerceptionConfig& config);

  void RecordEstimate(double t_s, const flight::StateEstimate& est);
  // Detects and geolocates; the detections wait out the latency. Frames without an estimate of
  // their capture step, tilted or turning are skipped.
  void OnCameraFrame(const cv::Mat& bgr, const swarm::PinholeIntrinsics& k, double capture_t_s);
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

  PerceptionConfig config_;
  swarm::VictimPerception perception_;
  std::vector<Estimate> history_;  // ring, one entry per control step
  std::size_t history_next_ = 0;
  std::vector<swarm::GroundDetection> visible_;
};

}  // namespace swarmbox::agent
