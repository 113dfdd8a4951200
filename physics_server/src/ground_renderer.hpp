// GroundRenderer: draws what a downward pinhole camera sees of the world, with OpenCV: a seeded
// procedural grass/soil ground texture, obstacle boxes (sides darker, tops lighter, painter's
// order by height), victims as warm hi-vis figures (orange body ellipse + amber head) and
// Gaussian pixel noise. Pure: no ODE, no clock; the same pose and seed give the same image.
//
// Pixel noise: i.i.d. Gaussian per pixel and channel, taken as a seeded random window of a large
// pre-drawn noise tile (scaled to the camera's noise_std), so a frame costs one add.
// Camera model: see camera_image.hpp. The ground is the plane z = 0 (mapped with one
// homography); pixels whose rays do not hit the ground are painted sky blue.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

#include "swarmbox/physics/airframe.hpp"
#include "swarmbox/physics/camera_image.hpp"
#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::physics {

// Pixel colours (BGR) of the victim figure: a classical detector can threshold R high, B low.
inline constexpr std::uint8_t kVictimBodyBgr[3] = {0, 120, 255};
inline constexpr std::uint8_t kVictimHeadBgr[3] = {40, 210, 255};

CameraIntrinsics IntrinsicsFor(const CameraSpec& spec);
// Optical frame pose from the body pose and the camera mounting (looking along body -z,
// image up = body +x).
Pose OpticalPose(const Pose& body, const CameraSpec& spec);

class GroundRenderer {
 public:
  // Builds the ground texture (about 10 MB for a 200 m world at 0.125 m per texel).
  explicit GroundRenderer(const WorldConfig& config);

  // Renders into `out` (resized as needed). noise_seed drives the pixel noise.
  void Render(const Pose& body_pose, const CameraSpec& spec, std::uint64_t noise_seed,
              CameraImage* out);

  double texel_m() const { return texel_m_; }

 private:
  const WorldConfig* config_;
  double texel_m_ = 0.125;
  double origin_x_m_ = 0;   // world x of texel column 0's left edge
  double top_y_m_ = 0;      // world y of texel row 0's top edge
  cv::Mat texture_;         // CV_8UC3
  cv::Mat noise_tile_;      // CV_16SC3 i.i.d. N(0, 1) * 16, drawn once; frames use seeded windows
};

}  // namespace swarmbox::physics
