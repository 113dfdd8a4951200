// The part of the SDK every brain library links a copy of: Context's argument readers, Output,
// the command names, and the library's table with the two functions the loader looks up.
// Nothing here may depend on more than the C++ standard library: a brain library gets this file's
// object and nothing else of SwarmBox.
#include "swarmbox/brain/brain.hpp"

#include <cerrno>
#include <cstdlib>
#include <stdexcept>

namespace swarmbox::brain {

const char* CommandName(Command::Kind kind) {
  switch (kind) {
    case Command::Kind::kArm: return "arm";
    case Command::Kind::kDisarm: return "disarm";
    case Command::Kind::kTakeoff: return "takeoff";
    case Command::Kind::kLand: return "land";
    case Command::Kind::kHold: return "hold";
    case Command::Kind::kPayloadAttach: return "payload_attach";
    case Command::Kind::kPayloadRelease: return "payload_release";
  }
  return "unknown";
}

void Output::Clear() {
  setpoint.clear();
  commands.clear();
  messages.clear();
  proposals.clear();
  status.clear();
  events.clear();
}

double Context::ArgDouble(const std::string& key, double fallback) const {
  const auto it = args.find(key);
  if (it == args.end()) return fallback;
  const std::string& text = it->second;
  // strtod, not from_chars: the same reading as the C brain's (the C locale: the agent never
  // calls setlocale). The whole text must be the number; inf and nan are refused.
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(begin, &end);
  if (text.empty() || end != begin + text.size() || errno == ERANGE || !std::isfinite(value)) {
    throw std::invalid_argument("brain argument " + key + ": expected a finite number, got \"" +
                                text + "\"");
  }
  return value;
}

std::string Context::ArgString(const std::string& key, const std::string& fallback) const {
  const auto it = args.find(key);
  return it == args.end() ? fallback : it->second;
}

std::vector<Registration>& LibraryRegistry() {
  static std::vector<Registration> registry;
  return registry;
}

}  // namespace swarmbox::brain

extern "C" int swarmbox_brain_abi_version() { return swarmbox::brain::kAbiVersion; }

extern "C" const std::vector<swarmbox::brain::Registration>* swarmbox_brain_registry() {
  return &swarmbox::brain::LibraryRegistry();
}
