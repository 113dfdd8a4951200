#include "swarmbox/depth/depth_message.hpp"

namespace swarmbox::depth {

bus::DepthSummary ToMessage(const std::string& drone, const DepthFrame& frame, const bus::Pose& camera_pose) {
  bus::DepthSummary m;
  m.drone = drone;
  m.capture_ns = frame.capture_ns;
  m.sim_time_ns = frame.release_ns;
  m.fill_rate = frame.summary.fill_rate;
  m.median_m = frame.summary.median_m;
  m.near_p5_m = frame.summary.near_p5_m;
  m.grid_cols = static_cast<std::uint32_t>(frame.summary.grid_cols);
  m.grid_rows = static_cast<std::uint32_t>(frame.summary.grid_rows);
  m.grid_m.assign(frame.summary.grid_m.begin(), frame.summary.grid_m.end());
  m.camera_pose = camera_pose;
  return m;
}

}  // namespace swarmbox::depth
