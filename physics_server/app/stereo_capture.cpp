#include "stereo_capture.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "swarmbox/physics/detail/mix64.hpp"
#include "swarmbox/physics/world_scene.hpp"

namespace swarmbox::physics {

using detail::Mix64;

namespace {

// Texture salts: a drone's body and its payload look different.
enum BodySalt : std::uint64_t { kDroneBodySalt = 1, kPayloadSalt = 2 };

// The other drones' bodies and every payload (the drone's own included: it hangs in its view)
// whose bounding sphere may be in the view of a camera at `camera_m` over a patch of `half_m`.
// The drone's own body is not: the cameras are under it, looking away from it.
void AddBodies(const World& world, std::size_t drone, const Vec3& camera_m, double half_m, StereoScene* scene) {
  scene->boxes.clear();
  for (std::size_t j = 0; j < world.drone_count(); ++j) {
    const DroneTruth t = world.Truth(j);
    const std::uint64_t seed = Mix64(static_cast<std::uint64_t>(j));
    if (j != drone) {
      const SceneBox body = DroneBodyBox(world.airframe(j), {t.position_m, t.attitude}, seed ^ kDroneBodySalt);
      if (MayBeInView(body, camera_m, half_m)) scene->boxes.push_back(body);
    }
    if (const PayloadSpec* p = world.payload(j); p != nullptr) {
      const SceneBox box = PayloadBox(*p, {t.payload_position_m, t.payload_attitude}, seed ^ kPayloadSalt);
      if (MayBeInView(box, camera_m, half_m)) scene->boxes.push_back(box);
    }
  }
}

}  // namespace

void PackStereoPair(const StereoFrame& frame, const std::string& drone, std::uint64_t step, std::int64_t time_ns,
                    bus::CameraImage* out) {
  const int w = frame.left.cols, h = frame.left.rows;
  out->drone = drone;
  out->step = step;
  out->sim_time_ns = time_ns;
  out->width_px = static_cast<std::uint32_t>(2 * w);
  out->height_px = static_cast<std::uint32_t>(h);
  out->row_stride_bytes = static_cast<std::uint32_t>(2 * w);
  out->encoding = "mono8";
  out->intrinsics.fx_px = frame.focal_px;
  out->intrinsics.fy_px = frame.focal_px;
  out->intrinsics.cx_px = frame.cx_px;
  out->intrinsics.cy_px = frame.cy_px;
  out->intrinsics.distortion = {};
  const Pose& p = frame.left_optical_pose;
  out->camera_pose.position_enu_m = {p.position_m.x, p.position_m.y, p.position_m.z};
  out->camera_pose.orientation_wxyz = {p.attitude.w, p.attitude.x, p.attitude.y, p.attitude.z};
  const auto row = static_cast<std::size_t>(w);
  out->data.resize(2 * row * static_cast<std::size_t>(h));
  for (int v = 0; v < h; ++v) {
    std::uint8_t* dst = out->data.data() + 2 * row * static_cast<std::size_t>(v);
    std::memcpy(dst, frame.left.ptr<std::uint8_t>(v), row);
    std::memcpy(dst + row, frame.right.ptr<std::uint8_t>(v), row);
  }
}

std::uint64_t StereoCapture::PeriodSteps(double rate_hz, std::int64_t control_period_ns) {
  // A rate so low that no pair would ever come (ParseStereoSpec only asks for > 0): capped, so the
  // conversion stays defined (2^40 steps: over a century at 250 Hz).
  constexpr double kMaxPeriodSteps = 1099511627776.0;
  const double steps = std::min(kMaxPeriodSteps, 1e9 / (rate_hz * static_cast<double>(control_period_ns)));
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(steps)));
}

double StereoCapture::PatchHalfSizeM(double height_m, double hfov_rad) {
  const double seen = std::max(0.0, height_m) * std::tan(hfov_rad / 2) * kPatchViewMargin + kPatchMargin_m;
  return std::min(seen, kMaxPatchHalfSize_m);
}

std::uint64_t StereoCapture::NoiseSeed(std::uint64_t world_seed, std::size_t drone, std::uint64_t step) {
  return Mix64(world_seed ^ Mix64(static_cast<std::uint64_t>(drone) ^ Mix64(step)));
}

StereoCapture::StereoCapture(const World& world) : period_steps_(world.drone_count(), 0) {
  for (std::size_t i = 0; i < world.drone_count(); ++i) {
    const StereoSpec& spec = world.airframe(i).stereo;
    if (!spec.enabled) continue;
    period_steps_[i] = PeriodSteps(spec.rate_hz, world.options().control_period_ns);
    any_ = true;
  }
}

bool StereoCapture::Due(std::size_t drone, std::uint64_t step) const {
  const std::uint64_t period = period_steps_.at(drone);
  return period > 0 && step % period == 0;
}

void StereoCapture::Capture(const World& world, std::size_t drone, std::uint64_t step, bus::CameraImage* out) {
  const StereoSpec& spec = world.airframe(drone).stereo;
  const DroneTruth truth = world.Truth(drone);
  const Pose body{truth.position_m, truth.attitude};
  const double half_m = PatchHalfSizeM(truth.position_m.z, spec.hfov_rad);
  scene_ = MakeWorldScene(world.config(), truth.position_m.x, truth.position_m.y, half_m,
                          world.config().ground_texture_seed);
  AddBodies(world, drone, body.position_m + Rotate(body.attitude, spec.offset_m), half_m, &scene_);
  renderer_.Render(body, spec, NoiseSeed(world.options().seed, drone, step), &frame_);
  PackStereoPair(frame_, world.drone_name(drone), step, world.time_ns(), out);
}

}  // namespace swarmbox::physics
