// The JSON Schemas of the recording's channels (ARCHITECTURE.md "Recordings", the contract's channel
// table): Foxglove's well-known schemas the channels use (foxglove.SceneUpdate, FrameTransforms,
// PoseInFrame, CompressedImage, Log: the names and fields Foxglove Studio recognises, so its 3D,
// image and log panels open a recording without configuration) and SwarmBox's own swarmbox.*
// schemas. Plus the `timestamp` every message carries: {"sec": S, "nsec": N} of simulated time.
//
//   ChannelSpec spec = MakeChannel("/drones/scout_1/truth", kDroneTruth);
//   ChannelId id = *sink.AddChannel(spec);
//   sink.Write(id, t_ns, "{\"timestamp\":" + JsonTimestamp(t_ns) + ",\"drone\":\"scout_1\",...}");
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/record/sink.hpp"

namespace swarmbox::record {

// Foxglove's well-known schemas.
inline constexpr std::string_view kSceneUpdate = "foxglove.SceneUpdate";
inline constexpr std::string_view kFrameTransforms = "foxglove.FrameTransforms";
inline constexpr std::string_view kPoseInFrame = "foxglove.PoseInFrame";
inline constexpr std::string_view kCompressedImage = "foxglove.CompressedImage";
inline constexpr std::string_view kLog = "foxglove.Log";
// SwarmBox's own (fields: the contract's channel table).
inline constexpr std::string_view kDroneTruth = "swarmbox.DroneTruth";
inline constexpr std::string_view kSetpoint = "swarmbox.Setpoint";
inline constexpr std::string_view kFlocking = "swarmbox.Flocking";
inline constexpr std::string_view kRaftState = "swarmbox.RaftState";
inline constexpr std::string_view kAgentStatus = "swarmbox.AgentStatus";
inline constexpr std::string_view kLinks = "swarmbox.Links";
inline constexpr std::string_view kSectors = "swarmbox.Sectors";
inline constexpr std::string_view kDetection = "swarmbox.Detection";

// foxglove.Log `level` values.
inline constexpr int kLogDebug = 1;
inline constexpr int kLogInfo = 2;
inline constexpr int kLogWarning = 3;
inline constexpr int kLogError = 4;
inline constexpr int kLogFatal = 5;

// Every schema name above, Foxglove's first.
const std::vector<std::string_view>& SchemaNames();

// The JSON Schema text (one JSON object, "title" = the name) of a schema above; "" for other names.
std::string_view SchemaText(std::string_view schema_name);

// {topic, schema_name, SchemaText(schema_name)}. Aborts (SWARMBOX_CHECK) for a name not above:
// the channel set is fixed in code.
ChannelSpec MakeChannel(std::string topic, std::string_view schema_name);

// Simulated time [ns] as Foxglove's time: {"sec":S,"nsec":N}, N in [0, 1e9).
std::string JsonTimestamp(std::uint64_t ns);
// The same as a document-tree mapping, for messages built with yaml::Node and yaml::EmitJson.
yaml::Node TimestampNode(std::uint64_t ns);
// Simulated seconds to ns (rounded to the nearest ns; negative and NaN give 0).
std::uint64_t SecondsToNs(double seconds);

}  // namespace swarmbox::record
