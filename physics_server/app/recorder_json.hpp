// The recording's messages as JSON (the contract's channel table, ARCHITECTURE.md "Recordings";
// schemas: record/foxglove_schemas.hpp). Pure: values in, one JSON object out, every message with
// its `timestamp` {sec, nsec} of simulated time. NaN (unset, unknown) is written as null.
//
//   std::string json = TruthJson(t_ns, "scout_1", truth);  // swarmbox.DroneTruth
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/bus/messages.hpp"
#include "swarmbox/physics/sensor_sample.hpp"
#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::physics {

// A small appending JSON writer: numbers with up to 9 significant digits (NaN/inf -> null),
// strings quoted as JSON. The caller keeps the structure well-formed.
// Commas are placed by the writer (a value after a value in the same container gets one).
class JsonOut {
 public:
  JsonOut& Key(std::string_view key);  // "key": inside an object
  JsonOut& Value(std::string_view json);  // a ready JSON value (e.g. JsonTimestamp)
  JsonOut& Num(double v);
  JsonOut& Int(std::int64_t v);
  JsonOut& Str(std::string_view s);
  JsonOut& Bool(bool b) { return Value(b ? "true" : "false"); }
  JsonOut& Vec(const std::array<double, 3>& v);  // [x, y, z]
  JsonOut& Open(char c);   // '{' or '['
  JsonOut& Close(char c);  // '}' or ']'
  JsonOut& Time(std::uint64_t t_ns);  // {"sec":..,"nsec":..}
  std::string Take() { return std::move(out_); }

 private:
  void Before();
  std::string out_;
  std::vector<bool> first_;  // per open container: nothing written in it yet
  bool after_key_ = false;
};

struct TruthPose {
  std::string_view drone;
  std::array<double, 3> position_m{};
  std::array<double, 3> velocity_m_s{};
  std::array<double, 4> orientation_wxyz{1, 0, 0, 0};
};

// /world (foxglove.SceneUpdate, once at t=0): entity `ground` (a flat cube over the geofence),
// one per obstacle (metadata kind=obstacle), one per victim (metadata kind=victim).
std::string WorldSceneJson(std::uint64_t t_ns, const WorldConfig& world);
// /tf (foxglove.FrameTransforms): parent `world`, child the drone's name.
std::string TransformsJson(std::uint64_t t_ns, std::span<const TruthPose> poses);
// /drones/<drone>/truth (swarmbox.DroneTruth).
std::string TruthJson(std::uint64_t t_ns, const TruthPose& pose);

// From an agent's Telemetry (its sim_time_ns is the timestamp):
std::string EstimateJson(const bus::Telemetry& t);   // foxglove.PoseInFrame, frame `world`
std::string SetpointJson(const bus::Telemetry& t);   // swarmbox.Setpoint
std::string FlockingJson(const bus::Telemetry& t);   // swarmbox.Flocking
bool HasFlocking(const bus::Telemetry& t);           // the terms are set (the drone flocks)
// /flocking (foxglove.SceneUpdate): entity `flocking/<drone>`, an arrow per term from the
// estimated position (separation red, alignment green, cohesion blue, sum white), 1 m per m/s.
std::string FlockingSceneJson(const bus::Telemetry& t);
std::string RaftJson(const bus::Telemetry& t);       // swarmbox.RaftState (pre_candidate: candidate)
std::string StatusJson(const bus::Telemetry& t);     // swarmbox.AgentStatus
std::string LinksJson(const bus::Telemetry& t);      // swarmbox.Links, from = the drone
std::string SectorsJson(const bus::Telemetry& t);    // swarmbox.Sectors
std::string DetectionJson(const bus::Detection& d);  // swarmbox.Detection

// /log (foxglove.Log): `message` the logfmt line, `name` its node, level 4 for error events
// (event=error, *_error, *_failed), 3 for warnings (*lost*, *rejected*, *missing*, *stopped*,
// *timeout*), 2 otherwise.
int LogLevelOf(std::string_view event);
std::string LogJson(std::uint64_t t_ns, std::string_view node, std::string_view event, std::string_view line);
// The same for a bus::Event (an agent's), its logfmt line rebuilt.
std::string EventLogJson(const bus::Event& e);

// /drones/<drone>/camera (foxglove.CompressedImage): base64 of the JPEG bytes.
std::string CompressedImageJson(std::uint64_t t_ns, std::string_view frame_id, std::span<const std::uint8_t> jpeg);
std::string Base64(std::span<const std::uint8_t> bytes);

}  // namespace swarmbox::physics
