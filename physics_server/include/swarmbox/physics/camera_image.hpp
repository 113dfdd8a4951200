// CameraImage: one frame of a drone's downward camera, with the pinhole intrinsics it was
// rendered with. Pixels are 8-bit BGR, row-major, `width_px * 3` bytes per row (wrap in
// cv::Mat(height_px, width_px, CV_8UC3, bgr.data()) without copying).
//
// Projection (no distortion): a point p_c in the camera frame (x right, y down, z along the
// optical axis = body -z) lands at u = fx * x/z + cx, v = fy * y/z + cy. Image up is body +x.
#pragma once

#include <cstdint>
#include <vector>

#include "swarmbox/physics/types.hpp"

namespace swarmbox::physics {

struct CameraIntrinsics {
  double fx_px = 0;
  double fy_px = 0;
  double cx_px = 0;
  double cy_px = 0;
};

struct CameraImage {
  std::int64_t time_ns = 0;
  int width_px = 0;
  int height_px = 0;
  CameraIntrinsics intrinsics;
  // True pose of the optical frame (x right, y down, z along the optical axis) at capture:
  // position [m, ENU] and the rotation optical frame -> world. For evaluation and the bus message.
  Pose camera_pose;
  std::vector<std::uint8_t> bgr;    // height_px * width_px * 3
};

}  // namespace swarmbox::physics
