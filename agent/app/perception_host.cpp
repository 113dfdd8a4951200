#include "perception_host.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::agent {
namespace {

using flight::Vec3;

constexpr std::size_t kHistory = 128;  // control steps of estimates kept (0.5 s at 250 Hz)

Status ReadCamera(const yaml::Node& cam, CameraSpec* c) {
  if (!cam.is_mapping()) return Error(ErrorCode::kInvalidArgument, "camera: expected a mapping", cam.Where());
  auto num = [&](std::string_view key, double* out) -> Status {
    const yaml::Node* n = cam.Find(key);
    if (n == nullptr) return Ok{};
    auto v = n->AsDouble();
    if (!v) return v.error();
    if (!(*v > 0)) return Error(ErrorCode::kInvalidArgument, "camera: " + std::string(key) + " must be > 0", n->Where());
    *out = *v;
    return Ok{};
  };
  double w = c->width_px, h = c->height_px;
  SWARMBOX_TRY(num("width_px", &w));
  SWARMBOX_TRY(num("height_px", &h));
  SWARMBOX_TRY(num("hfov_rad", &c->hfov_rad));
  SWARMBOX_TRY(num("rate_hz", &c->rate_hz));
  if (!(c->hfov_rad < M_PI)) return Error(ErrorCode::kInvalidArgument, "camera: hfov_rad must be < pi", cam.Where());
  c->width_px = static_cast<int>(w);
  c->height_px = static_cast<int>(h);
  if (const yaml::Node* off = cam.Find("offset_m")) {
    std::array<double, 3> a{};
    SWARMBOX_TRY(yaml::Decode(*off, &a));
    c->offset_m = Vec3(a[0], a[1], a[2]);
  }
  return Ok{};
}

swarm::PerceptionParams PerceptionFor(double latency_s) {
  swarm::PerceptionParams p;
  p.latency_s = latency_s;
  return p;
}

}  // namespace

Result<CameraSpec> LoadCameraSpec(const std::string& airframe_path) {
  auto doc = yaml::ParseFile(airframe_path);
  if (!doc) return doc.error();
  const yaml::Node* cam = doc->is_mapping() ? doc->Find("camera") : nullptr;
  if (cam == nullptr) return Error(ErrorCode::kInvalidArgument, "airframe has no camera mapping", doc->Where());
  CameraSpec c;
  SWARMBOX_TRY(ReadCamera(*cam, &c));
  return c;
}

Result<std::unique_ptr<PerceptionHost>> PerceptionHost::Create(const PerceptionConfig& config) {
  if (!(config.inference_latency_s >= 0)) {
    return Error(ErrorCode::kInvalidArgument, "perception: inference latency must be >= 0");
  }
  return std::unique_ptr<PerceptionHost>(new PerceptionHost(config));
}

PerceptionHost::PerceptionHost(const PerceptionConfig& config)
    : config_(config), perception_(PerceptionFor(config.inference_latency_s)), history_(kHistory) {}

void PerceptionHost::RecordEstimate(double t_s, const flight::StateEstimate& est) {
  history_[history_next_] = {t_s, est.pos_m, est.att, est.rate_radps};
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
  if (best->rate_radps.norm() > config_.max_rate_rad_s) return;
  const swarm::OpticalPose pose = swarm::OpticalPoseFromBody(best->pos_m, best->att, config_.camera.offset_m);
  (void)perception_.ProcessFrame(bgr, k, pose, capture_t_s);
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
