#include "perception_host.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "swarmbox/depth/depth_surface.hpp"

namespace swarmbox::agent {
namespace {

using flight::Vec3;

constexpr std::size_t kHistory = 128;  // control steps of estimates kept (0.5 s at 250 Hz)

swarm::PerceptionParams PerceptionFor(const PerceptionConfig& config) {
  swarm::PerceptionParams p;
  p.latency_s = config.inference_latency_s;
  p.thermal = config.thermal_evidence;
  return p;
}

}  // namespace

// A depth frame's surface as geolocation asks for it: the height near a point within a radius. The
// depth::DepthSurface is built on the first question (the depth's pixels back-projected once).
class DepthHeights : public swarm::GroundHeightSource {
 public:
  DepthHeights(const depth::DepthFrame& frame, const bus::Pose& camera_pose, const depth::CameraIntrinsics& intrinsics,
               double radius_m)
      : depth_m_(frame.depth_m),
        capture_t_s_(static_cast<double>(frame.capture_ns) * 1e-9),
        camera_pose_(camera_pose),
        intrinsics_(intrinsics),
        radius_m_(radius_m) {}
  std::optional<double> HeightNear(double x_m, double y_m) const override {
    if (!surface_) surface_.emplace(depth_m_, intrinsics_, camera_pose_, depth::DepthSurfaceConfig{});
    return surface_->HeightNear(x_m, y_m, radius_m_);
  }
  double capture_t_s() const { return capture_t_s_; }

 private:
  cv::Mat depth_m_;
  double capture_t_s_;
  bus::Pose camera_pose_;
  depth::CameraIntrinsics intrinsics_;
  double radius_m_;
  mutable std::optional<depth::DepthSurface> surface_;  // a cache: built on the first question
};

PerceptionHost::~PerceptionHost() = default;

Result<std::unique_ptr<PerceptionHost>> PerceptionHost::Create(const PerceptionConfig& config) {
  if (!(config.inference_latency_s >= 0)) {
    return Error(ErrorCode::kInvalidArgument, "perception: inference latency must be >= 0");
  }
  if (!(config.depth_max_age_s >= 0) || !(config.depth_height_radius_m > 0)) {
    return Error(ErrorCode::kInvalidArgument, "perception: depth_max_age_s must be >= 0 and depth_height_radius_m > 0");
  }
  return std::unique_ptr<PerceptionHost>(new PerceptionHost(config));
}

PerceptionHost::PerceptionHost(const PerceptionConfig& config)
    : config_(config), perception_(PerceptionFor(config)), history_(kHistory) {}

void PerceptionHost::RecordEstimate(double t_s, const flight::StateEstimate& est) {
  history_[history_next_] = {t_s, est.pos_m, est.att, est.rate_rad_s};
  history_next_ = (history_next_ + 1) % history_.size();
}

void PerceptionHost::OnCameraFrame(const cv::Mat& bgr, const swarm::PinholeIntrinsics& k, double capture_t_s) {
  const Estimate* best = nullptr;
  for (const Estimate& e : history_) {
    if (e.t_s < 0) continue;
    if (best == nullptr || std::abs(e.t_s - capture_t_s) < std::abs(best->t_s - capture_t_s)) best = &e;
  }
  // The estimate of the capture step (or the nearest one within a step or two of it).
  if (best == nullptr || std::abs(best->t_s - capture_t_s) > 0.02) return;
  // Geolocation needs a steady camera: a tilted or turning drone multiplies attitude errors.
  const Vec3 up = best->att * Vec3::UnitZ();
  if (std::acos(std::clamp(up.z(), -1.0, 1.0)) > config_.max_tilt_rad) return;
  if (best->rate_rad_s.norm() > config_.max_rate_rad_s) return;
  const airframe::Vec3& offset = config_.camera.offset_m;
  const swarm::OpticalPose pose = swarm::OpticalPoseFromBody(best->pos_m, best->att, Vec3(offset.x, offset.y, offset.z));
  // The thermal frame taken with this one (the same capture step), seen from the same estimate.
  std::optional<swarm::ThermalView> thermal;
  if (config_.thermal.enabled && thermal_t_s_ >= 0 && std::abs(thermal_t_s_ - capture_t_s) < 1e-6) {
    const airframe::Vec3& t = config_.thermal.offset_m;
    thermal = swarm::ThermalView{thermal_kelvin_, thermal_k_,
                                 swarm::OpticalPoseFromBody(best->pos_m, best->att, Vec3(t.x, t.y, t.z))};
  }
  (void)perception_.ProcessFrame(bgr, k, pose, capture_t_s, SurfaceFor(capture_t_s),
                                 thermal ? &*thermal : nullptr);
}

void PerceptionHost::OnThermalFrame(const cv::Mat& kelvin, const swarm::PinholeIntrinsics& k,
                                    double capture_t_s) {
  if (!config_.thermal.enabled || kelvin.type() != CV_32F) return;
  kelvin.copyTo(thermal_kelvin_);
  thermal_k_ = k;
  thermal_t_s_ = capture_t_s;
}

void PerceptionHost::OnDepthFrame(const depth::DepthFrame& frame, const bus::Pose& camera_pose,
                                  const depth::CameraIntrinsics& intrinsics) {
  depth_ = std::make_unique<const DepthHeights>(frame, camera_pose, intrinsics, config_.depth_height_radius_m);
}

const swarm::GroundHeightSource* PerceptionHost::SurfaceFor(double capture_t_s) const {
  if (!depth_ || std::abs(depth_->capture_t_s() - capture_t_s) > config_.depth_max_age_s) return nullptr;
  return depth_.get();
}

void PerceptionHost::PopVisible(double t_s, std::vector<brain::Detection>* out) {
  visible_.clear();
  perception_.PopVisible(t_s, &visible_);
  for (const swarm::GroundDetection& d : visible_) {
    brain::Detection b;
    b.t_ns = static_cast<std::int64_t>(d.capture_time_s * 1e9);  // as the bus::Detection always had it
    b.label = "victim";
    b.confidence = d.confidence;
    b.position_m = {d.position_m.x(), d.position_m.y(), d.position_m.z()};
    b.sigma_m = d.sigma_m;
    out->push_back(std::move(b));
  }
}

}  // namespace swarmbox::agent
