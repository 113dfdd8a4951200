// trajectories.png: the top-down view of a trial: every drone's path from truth.csv (one colour
// per drone, start marked with a circle, end with a cross), the world's obstacles (boxes, rotated
// by yaw) and victims (stars), and detections reported in the logs (small rings), over a grid with
// a 10 m spacing and the geofence. Drawn with OpenCV.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::runner {

struct TrackPoint {
  double t_s = 0;
  double x_m = 0;  // ENU east
  double y_m = 0;  // ENU north
};

// Parses truth.csv (header with t_s, drone, x_m, y_m columns; other columns ignored). Tracks keep
// the order drones first appear in. kInvalidArgument naming the line on malformed rows.
Result<std::vector<std::pair<std::string, std::vector<TrackPoint>>>> ParseTruthCsv(
    std::string_view csv);

struct WorldPicture {
  double size_x_m = 200;
  double size_y_m = 200;
  struct Box {
    double x_m, y_m, sx_m, sy_m, yaw_deg;
    bool tree = false;  // kind: tree, drawn as a round crown
  };
  std::vector<Box> obstacles;
  struct Victim {
    std::string id;
    double x_m, y_m;
  };
  std::vector<Victim> victims;
};

// The parts of a world file the picture needs (geofence, obstacles, victims); other keys are the
// physics server's business and ignored here.
Result<WorldPicture> LoadWorldPicture(const std::string& path);

struct Detection {
  std::string drone;
  double x_m = 0;
  double y_m = 0;
  bool confirmed = false;
};

// Draws and writes a PNG of about `size_px` square.
Status DrawTrajectories(
    const std::vector<std::pair<std::string, std::vector<TrackPoint>>>& tracks,
    const WorldPicture& world, const std::vector<Detection>& detections, const std::string& path,
    int size_px = 1000);

}  // namespace swarmbox::runner
