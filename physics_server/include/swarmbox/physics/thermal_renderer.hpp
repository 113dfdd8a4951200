// ThermalRenderer: what a downward radiometric LWIR camera (airframe::ThermalSpec, a FLIR Boson
// 320) sees of the world, with OpenCV, and the truth of which people it drew.
//
//   ThermalRenderer renderer(world_config);   // builds the scene and its temperatures once
//   ThermalImage img;
//   renderer.Render(body_pose, thermal_spec, noise_seed, &img, &people);
//   // img.centikelvin[v * img.width_px + u] / 100.0: the apparent temperature [K] there
//
// The world is the RGB camera's (GroundRenderer: the same terrain, people, cover, distractors,
// obstacles and trees, the same shadows), each surface at the temperature of a steady-state
// energy balance with the sunlight it absorbs and, for people, the body's warmth through their
// clothing (detail/thermal_scene.hpp; physics_server/README.md "Thermal"): at night or under cloud
// people stand out of the ground; in a clear noon's sun dark rubble, tarps and backpacks reach
// their clothing's temperature and only the warmth through it tells them apart.
// The camera: the optics' blur (psf_sigma_px), the core's temporal noise (netd_k) and a frame's
// radiometric offset (offset_std_k), from `noise_seed`; quantised to 0.01 K.
//
// Pure: no ODE, no clock; the same pose and seed give the same image. Not thread-safe (scratch
// images are reused); one renderer per thread. Keeps a pointer to `config`: the WorldConfig must
// outlive the renderer.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/airframe/thermal_spec.hpp"
#include "swarmbox/physics/camera_image.hpp"
#include "swarmbox/physics/ground_renderer.hpp"
#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::physics {
namespace detail {
struct RenderScene;
}

inline constexpr double kThermalCountsPerK = 100.0;  // ThermalImage::centikelvin: 0.01 K a count

// One radiometric frame: the apparent temperature per pixel, in hundredths of a kelvin
// (row-major; wrap in cv::Mat(height_px, width_px, CV_16U, centikelvin.data()) without copying).
// Geometry as CameraImage's (camera_image.hpp).
struct ThermalImage {
  std::int64_t time_ns = 0;
  int width_px = 0;
  int height_px = 0;
  CameraIntrinsics intrinsics;
  Pose camera_pose;  // the optical frame at capture (truth)
  std::vector<std::uint16_t> centikelvin;
};

CameraIntrinsics IntrinsicsFor(const airframe::ThermalSpec& spec);

class ThermalRenderer {
 public:
  explicit ThermalRenderer(const WorldConfig& config);
  ~ThermalRenderer();
  ThermalRenderer(const ThermalRenderer&) = delete;
  ThermalRenderer& operator=(const ThermalRenderer&) = delete;

  // Renders into `out` (resized as needed); `people` (optional) receives what was drawn of each
  // person in view (as GroundRenderer's).
  void Render(const Pose& body_pose, const airframe::ThermalSpec& spec, std::uint64_t noise_seed,
              ThermalImage* out, std::vector<VisiblePerson>* people = nullptr);

  double air_k() const { return air_k_; }  // the world's air temperature [K]

 private:
  void ApplySensor(const airframe::ThermalSpec& spec, std::uint64_t noise_seed, cv::Mat* dst);

  const WorldConfig* config_;
  std::unique_ptr<detail::RenderScene> scene_;  // in kelvin
  double air_k_ = 293.15;
  cv::Mat img_, blurred_, noise_, labels_, scratch_;
};

}  // namespace swarmbox::physics
