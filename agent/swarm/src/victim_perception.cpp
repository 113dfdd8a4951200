#include "swarmbox/swarm/victim_perception.hpp"

#include <algorithm>
#include <cmath>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {

VictimPerception::VictimPerception(const PerceptionParams& params)
    : params_(params),
      detector_(params.detector),
      thermal_(params.thermal),
      queue_(params.latency_s, params.queue_capacity) {
  blobs_.reserve(32);
}

int VictimPerception::ProcessFrame(const cv::Mat& bgr, const PinholeIntrinsics& k,
                                   const OpticalPose& camera_pose, double capture_time_s,
                                   const GroundHeightSource* surface, const ThermalView* thermal) {
  SWARMBOX_CHECK(k.fx_px > 0 && k.fy_px > 0);
  const double height = camera_pose.position_m.z() - params_.ground_z_m;
  if (height <= 0.5) {  // on or near the ground: nothing sensible to see
    blobs_.clear();
    return 0;
  }
  detector_.Detect(bgr, k, camera_pose, params_.ground_z_m, &blobs_);
  int queued = 0;
  for (const ImageBlob& b : blobs_) {
    if (thermal == nullptr && b.confidence < params_.min_confidence) continue;
    const std::optional<Eigen::Vector3d> p =
        surface == nullptr ? PixelToGround(b.centroid_px, k, camera_pose, params_.ground_z_m)
                           : PixelToSurface(b.centroid_px, k, camera_pose, params_.ground_z_m, *surface);
    if (!p) continue;
    double confidence = b.confidence;
    if (thermal != nullptr) {
      confidence = thermal_.Apply(confidence, *thermal, *p);
      if (confidence < params_.min_confidence) continue;
    }
    GroundDetection d;
    d.position_m = *p;
    d.sigma_m = GroundSigma((*p - camera_pose.position_m).norm(), params_.position_sigma_m,
                            params_.attitude_sigma_rad, params_.pixel_sigma_px, k.fx_px);
    d.confidence = confidence;
    d.pixel = b.centroid_px;
    d.area_px = b.area_px;
    d.viewer_m = camera_pose.position_m;
    queue_.Push(d, capture_time_s);
    ++queued;
  }
  return queued;
}

}  // namespace swarmbox::swarm
