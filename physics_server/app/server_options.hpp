// ServerOptions: what swarmbox-physics runs (world, drones, pacing, outputs, bus), and the
// parsers for its drone specifications.
//
//   --drone scout_1:x500:0,0,0            name:airframe:x,y,z[:yaw_deg[:payload[:attached]]]
//   --drones drones.yaml                  a list of {name, airframe, pose: [x, y, z], yaw_deg,
//                                         payload, payload_attached} (the trial's `drones:` shape)
// An airframe is a name looked up as <airframes_dir>/<name>.yaml, or a path to a .yaml file.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::physics {

struct DroneSpec {
  std::string name;
  std::string airframe;     // name or path
  double x_m = 0, y_m = 0, z_m = 0;
  double yaw_deg = 0;
  std::string payload;
  bool payload_attached = false;
  std::string where;        // "--drone #2" or "drones.yaml:3:5", for messages
};

struct ServerOptions {
  std::string world_path;
  std::vector<DroneSpec> drones;
  std::string airframes_dir;            // default: <dir of the world file>/../airframes
  double rtf = 1.0;                     // 0 = as fast as possible
  std::uint64_t seed = 1;
  std::string truth_path = "truth.csv"; // "" = none
  double truth_rate_hz = 50;
  std::string sim_interface = "lo";
  // Discovery/ParticipantIndex of the server's sim participant (bus/cyclone_config.hpp): 0 in a
  // trial, where the agents name the server's container as their one discovery peer; -1: none.
  int participant_index = -1;
  int domain = 0;
  std::string middleware = "cyclonedds";
  double max_sim_time_s = 0;            // 0 = until SIGTERM
  double step_timeout_s = 1.0;          // silence that marks a drone lost
  double join_timeout_s = 30.0;         // before a drone's first answer
  int physics_rate_hz = 1000;
  int control_rate_hz = 250;
  bool cameras = true;
  double clock_every_s = 10.0;          // simulated s between event=clock lines; 0 = none
  std::string radio_plan_path;          // --radio-plan: radio_plan.hpp JSON; "" = none
  std::string radio_model = "netem";    // --radio-model channel|netem
  std::string radio_profile_path;       // --radio-profile (required with channel)
  // The recording (recorder.hpp): --record PATH writes recording.mcap; "" = none.
  std::string record_path;
  double record_rate_hz = 10.0;
  double record_camera_hz = 1.0;
  double record_camera_scale = 0.5;
  int record_jpeg_quality = 75;
  // --view ADDR:PORT: serve the same channels live (record::LiveServer); "" = none.
  std::string view_addr;
};

// "name:airframe:x,y,z[:yaw_deg[:payload[:attached]]]".
Result<DroneSpec> ParseDroneArg(const std::string& text);
// A YAML list of drones (or a mapping with a `drones:` list).
Result<std::vector<DroneSpec>> ParseDronesFile(const yaml::Node& root);
Result<std::vector<DroneSpec>> LoadDronesFile(const std::string& path);
// Resolves an airframe name or path against airframes_dir.
std::string AirframePathFor(const std::string& airframe, const std::string& airframes_dir);

}  // namespace swarmbox::physics
