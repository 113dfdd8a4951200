#include "swarmbox/bus/messages.hpp"

namespace swarmbox::bus {

std::string_view MessageTypeName(MessageType type) {
  switch (type) {
    case MessageType::kClockTick: return "swarmbox::msg::ClockTick";
    case MessageType::kSensorSample: return "swarmbox::msg::SensorSample";
    case MessageType::kActuatorCommand: return "swarmbox::msg::ActuatorCommand";
    case MessageType::kCameraImage: return "swarmbox::msg::CameraImage";
    case MessageType::kWorldCommand: return "swarmbox::msg::WorldCommand";
    case MessageType::kDroneState: return "swarmbox::msg::DroneState";
    case MessageType::kRaftMessage: return "swarmbox::msg::RaftMessage";
    case MessageType::kDetection: return "swarmbox::msg::Detection";
    case MessageType::kRadioPing: return "swarmbox::msg::RadioPing";
    case MessageType::kBrainMessage: return "swarmbox::msg::BrainMessage";
    case MessageType::kEvent: return "swarmbox::msg::Event";
    case MessageType::kBrainInput: return "swarmbox::msg::BrainInput";
    case MessageType::kBrainOutput: return "swarmbox::msg::BrainOutput";
    case MessageType::kTelemetry: return "swarmbox::msg::Telemetry";
    case MessageType::kDepthSummary: return "swarmbox::msg::DepthSummary";
  }
  return "swarmbox::msg::<unknown>";
}

}  // namespace swarmbox::bus
