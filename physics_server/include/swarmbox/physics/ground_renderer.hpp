// GroundRenderer: draws what a downward pinhole camera sees of the world, with OpenCV, and tells
// the truth of what it drew (which people, where, how much of them is visible).
//
//   GroundRenderer renderer(world_config);          // builds the ground texture once
//   std::vector<VisiblePerson> people;
//   renderer.Render(body_pose, airframe.camera, noise_seed, &image, &people);
//
// What it draws (world YAML, trials/worlds/open_field.yaml documents the keys):
// - the ground: a seeded procedural texture of the world's terrain (grass, soil, gravel, rubble or
//   a mix, with ponds and muddy water edges), the static shadows of obstacles, trees, people and
//   distractors from the sun's direction baked in; pixels whose rays miss the ground are sky;
// - people (victims) by pose (lying, sitting, curled, standing) in their clothing colour with a
//   skin-toned head, partly hidden under rubble or vegetation (`cover`);
// - distractors (tarps, cones, backpacks, debris, bright rocks) and obstacles: boxes (sides
//   darker, tops lighter) and trees (round crowns), painter's order by height;
// - sensor effects: the light level and colour of the time of day and overcast (lighting), the
//   camera's exposure (gain, clipping), motion blur from the body's angular rates over the
//   exposure time, lens vignetting and Gaussian pixel noise (a seeded window of a pre-drawn tile).
// Without `lighting`, `terrain`, clothing, poses and distractors in the world (the defaults) it
// draws the original look: grass/soil texture, hi-vis orange figures with amber heads, flat light.
//
// Pure: no ODE, no clock; the same pose, rates and seed give the same image. Not thread-safe
// (scratch images are reused); one renderer per thread. Keeps a pointer to `config`: the
// WorldConfig must outlive the renderer.
// Camera model: see camera_image.hpp. The ground is the plane z = 0 (mapped with one homography).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/physics/airframe.hpp"
#include "swarmbox/physics/camera_image.hpp"
#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::physics {
namespace detail {
struct RenderScene;
}

// Pixel colours (BGR) of the default victim figure (no clothing_bgr): orange body, amber head.
inline constexpr std::uint8_t kVictimBodyBgr[3] = {0, 120, 255};
inline constexpr std::uint8_t kVictimHeadBgr[3] = {40, 210, 255};

// Ground truth of one person in a rendered frame: for training and evaluating detectors, never
// for the agent. Listed only when some of the person is visible in the image.
struct VisiblePerson {
  std::string id;            // the victim's id in the world
  cv::Rect box_px;           // the figure's extent in the image, clipped to it (covered parts included)
  double visible_fraction;   // (0, 1]: share of the figure's projected area that is seen (inside the
                             // image, not under cover, an obstacle or a tree)
};

CameraIntrinsics IntrinsicsFor(const CameraSpec& spec);
// Optical frame pose from the body pose and the camera mounting (looking along body -z,
// image up = body +x).
Pose OpticalPose(const Pose& body, const CameraSpec& spec);

class GroundRenderer {
 public:
  // Builds the ground texture (about 20 MB for a 200 m world at 0.125 m per texel).
  explicit GroundRenderer(const WorldConfig& config);
  ~GroundRenderer();
  GroundRenderer(const GroundRenderer&) = delete;
  GroundRenderer& operator=(const GroundRenderer&) = delete;

  // Renders into `out` (resized as needed); noise_seed drives the pixel noise and the exposure
  // jitter. `people` (optional) receives what was drawn of each person in view.
  void Render(const Pose& body_pose, const CameraSpec& spec, std::uint64_t noise_seed, CameraImage* out,
              std::vector<VisiblePerson>* people = nullptr);
  // Same, with motion blur from the body's angular rates [rad/s, body FLU] over the exposure.
  void Render(const Pose& body_pose, const Vec3& body_rates_rad_s, const CameraSpec& spec,
              std::uint64_t noise_seed, CameraImage* out, std::vector<VisiblePerson>* people = nullptr);

  double texel_m() const { return texel_m_; }

 private:
  const WorldConfig* config_;
  std::unique_ptr<detail::RenderScene> scene_;  // texture and drawables, built once
  double texel_m_ = 0.125;
  cv::Mat noise_tile_;      // CV_16SC3 i.i.d. N(0, 1) * 16, drawn once; frames use seeded windows
  cv::Mat labels_;          // CV_16U person index + 1 per pixel (only when truth is asked for)
  cv::Mat scratch_;         // CV_8U, the figure's full area
  cv::Mat blur_pad_, blur_acc_;
  cv::Mat gain_map_;        // CV_8UC3 light colour x vignetting, 100 = unit gain
  double gain_map_vignetting_ = -1;
};

}  // namespace swarmbox::physics
