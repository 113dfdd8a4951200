#include "swarmbox/bus/topics.hpp"

#include <string>

namespace swarmbox::bus {
namespace {

bool IsAsciiLetter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
bool IsAsciiDigit(char c) { return c >= '0' && c <= '9'; }

std::string Describe(char c) {
  if (c >= 0x21 && c <= 0x7e) return std::string("'") + c + "'";
  return "byte " + std::to_string(static_cast<int>(static_cast<unsigned char>(c)));
}

}  // namespace

std::string_view QosName(Qos qos) {
  switch (qos) {
    case Qos::kLockstep: return "lockstep";
    case Qos::kRadio: return "radio";
    case Qos::kState: return "state";
  }
  return "unknown";
}

std::string SensorTopic(std::string_view drone) { return "sim/" + std::string(drone) + "/sensor"; }
std::string CameraTopic(std::string_view drone) { return "sim/" + std::string(drone) + "/camera"; }
std::string StereoTopic(std::string_view drone) { return "sim/" + std::string(drone) + "/stereo"; }
std::string DepthImageTopic(std::string_view drone) { return "sim/" + std::string(drone) + "/depth"; }
std::string OffboardInputTopic(std::string_view drone) {
  return "offboard/" + std::string(drone) + "/input";
}
std::string OffboardOutputTopic(std::string_view drone) {
  return "offboard/" + std::string(drone) + "/output";
}

Status ValidateTopicName(std::string_view topic) {
  static constexpr std::string_view kRule =
      "topic names hold only ASCII letters, digits, '_' and '/', and start with a letter";
  if (topic.empty()) {
    return Error(ErrorCode::kInvalidArgument, "empty topic name: " + std::string(kRule));
  }
  if (!IsAsciiLetter(topic.front())) {
    return Error(ErrorCode::kInvalidArgument, "topic name '" + std::string(topic) +
                                                  "' starts with " + Describe(topic.front()) +
                                                  ": " + std::string(kRule));
  }
  for (char c : topic) {
    if (!IsAsciiLetter(c) && !IsAsciiDigit(c) && c != '_' && c != '/') {
      return Error(ErrorCode::kInvalidArgument, "topic name '" + std::string(topic) +
                                                    "' contains " + Describe(c) + ": " +
                                                    std::string(kRule));
    }
  }
  return Ok{};
}

Status ValidateDroneName(std::string_view drone) {
  static constexpr std::string_view kRule = "drone names are non-empty [A-Za-z0-9_]+";
  if (drone.empty()) return Error(ErrorCode::kInvalidArgument, "empty drone name: " + std::string(kRule));
  for (char c : drone) {
    if (!IsAsciiLetter(c) && !IsAsciiDigit(c) && c != '_') {
      return Error(ErrorCode::kInvalidArgument, "drone name '" + std::string(drone) + "' contains " +
                                                    Describe(c) + ": " + std::string(kRule));
    }
  }
  return Ok{};
}

}  // namespace swarmbox::bus
