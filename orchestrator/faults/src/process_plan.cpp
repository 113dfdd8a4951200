#include "swarmbox/faults/process_plan.hpp"

namespace swarmbox::faults {

std::string DockerActionText(const DockerAction& a) {
  switch (a.kind) {
    case DockerAction::Kind::kKill: return "kill " + a.container + " " + a.signal;
    case DockerAction::Kind::kStop: return "stop " + a.container + " (timeout " + std::to_string(a.timeout_s) + "s)";
    case DockerAction::Kind::kStart: return "start " + a.container;
    case DockerAction::Kind::kPause: return "pause " + a.container;
    case DockerAction::Kind::kUnpause: return "unpause " + a.container;
    case DockerAction::Kind::kRestart:
      return "restart " + a.container + " (timeout " + std::to_string(a.timeout_s) + "s)";
  }
  return "";
}

ProcessPlan PlanProcessFault(const ProcessFault& fault, const std::vector<std::string>& containers,
                             bool has_duration) {
  using K = DockerAction::Kind;
  ProcessPlan plan;
  for (const auto& c : containers) {
    switch (fault.action) {
      case ProcessAction::kKill:
        plan.apply.push_back({K::kKill, c, fault.signal, 0});
        if (has_duration) plan.undo.push_back({K::kStart, c, "", 0});
        break;
      case ProcessAction::kStop:
        plan.apply.push_back({K::kStop, c, "", fault.timeout_s});
        if (has_duration) plan.undo.push_back({K::kStart, c, "", 0});
        break;
      case ProcessAction::kPause:
        plan.apply.push_back({K::kPause, c, "", 0});
        if (has_duration) plan.undo.push_back({K::kUnpause, c, "", 0});
        break;
      case ProcessAction::kRestart:
        plan.apply.push_back({K::kRestart, c, "", fault.timeout_s});
        break;
    }
  }
  return plan;
}

}  // namespace swarmbox::faults
