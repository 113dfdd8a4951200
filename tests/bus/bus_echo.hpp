// The echo side of two-process bus tests and of the `bus` benchmark: subscribes to one topic and
// answers every sample on another, until told to stop.
//
// Kinds:
//   lockstep  SensorSample on SensorTopic(drone) -> ActuatorCommand on kActuatorTopic (keyed by
//             drone) with the same step (what an agent does for the physics server), Qos::kLockstep
//   small     RaftMessage on kBenchPingTopic -> the same message on kBenchPongTopic, kLockstep
//   large     CameraImage on kBenchPingTopic -> the same message on kBenchPongTopic, kLockstep
//   fleet     `drones` agents drone_0..drone_<n-1> in this process (one participant), each with
//             its own sensor reader and actuator writer, answering its SensorSample with an
//             ActuatorCommand of the same step from the subscriber callback
// Options as key/value pairs: backend, domain, interface (default lo), kind, drone (default
// drone_1), drones (fleet size, default 1). The swarmbox-bus-echo test helper and `swarmbox-bench bus --role=echo` both run it.
#pragma once

#include <atomic>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::bus::testing {

inline constexpr std::string_view kBenchPingTopic = "bench/ping";
inline constexpr std::string_view kBenchPongTopic = "bench/pong";

struct EchoOptions {
  std::string backend = "cyclonedds";
  int domain_id = 0;
  std::string interface = "lo";
  std::string kind = "lockstep";
  std::string drone = "drone_1";
  int drones = 1;
};

// kInvalidArgument naming the bad key or value.
Result<EchoOptions> EchoOptionsFromMap(const std::map<std::string, std::string>& options);

// The options as `--key=value` arguments.
std::vector<std::string> EchoArgs(const EchoOptions& options);

// Serves until `stop` becomes true (checked every 50 ms). Prints `echo ready` on stderr once its
// publisher and subscriber exist. Errors: participant/entity creation, or a failed publish.
Status RunEcho(const EchoOptions& options, const std::atomic<bool>& stop);

}  // namespace swarmbox::bus::testing
