// The bus form of a depth frame: bus::DepthSummary on bus::kDepthTopic (keyed by drone).
#pragma once

#include <string>

#include "swarmbox/bus/messages.hpp"
#include "swarmbox/depth/depth_camera.hpp"

namespace swarmbox::depth {

// `camera_pose`: the left camera's optical frame at the exposure (position ENU, rotation optical
// -> world, w x y z).
bus::DepthSummary ToMessage(const std::string& drone, const DepthFrame& frame, const bus::Pose& camera_pose);

}  // namespace swarmbox::depth
