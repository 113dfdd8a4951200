// record::Sink: where a trial's recorded channels go. A channel is one topic of JSON messages with a
// JSON Schema (Foxglove's well-known schemas, or SwarmBox's own); every message is stamped with the
// simulated time it describes. Two sinks: McapWriter (recording.mcap) and LiveServer (the Foxglove
// WebSocket protocol and the built-in page). The channels themselves: ARCHITECTURE.md, "Recordings".
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"

namespace swarmbox::record {

struct ChannelSpec {
  std::string topic;        // e.g. "/drones/scout_1/truth"
  std::string schema_name;  // e.g. "foxglove.PoseInFrame", "swarmbox.RaftState"
  std::string schema;       // JSON Schema text (MCAP schema encoding "jsonschema")
};

using ChannelId = std::uint32_t;

class Sink {
 public:
  virtual ~Sink() = default;
  virtual Result<ChannelId> AddChannel(const ChannelSpec& spec) = 0;
  // log_time_ns: the simulated time of the message [ns]. json: one JSON object.
  virtual Status Write(ChannelId channel, std::uint64_t log_time_ns, std::string_view json) = 0;
};

}  // namespace swarmbox::record
