// GroundDetection: one victim detection geolocated on the ground, the output of the perception
// pipeline (victim_detector.hpp + geolocation.hpp, delayed by latency_queue.hpp) and an input of
// the scout's behaviour (scout_behaviour.hpp), which turns it into a Raft ReportSighting.
// On the mesh it travels as bus::Detection (label "victim").
#pragma once

#include <Eigen/Core>

namespace swarmbox::swarm {

struct GroundDetection {
  double capture_time_s = 0.0;  // simulated time the image was taken [s]
  double visible_time_s = 0.0;  // when the rest of the agent may see it (capture + latency) [s]
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // on the ground plane, world ENU [m]
  double sigma_m = 0.0;         // 1-sigma horizontal uncertainty of position_m [m]
  double confidence = 0.0;      // [0, 1]
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // blob centroid (u right, v down) [px]
  double area_px = 0.0;         // blob area [px^2]
  // Where the camera was (its estimated position at capture, world ENU [m]): the viewpoint the
  // mission's fusion needs to tell a second view from the same one (sighting_fusion.hpp).
  Eigen::Vector3d viewer_m = Eigen::Vector3d::Zero();
};

}  // namespace swarmbox::swarm
