#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "swarmbox/swarm/thermal_evidence.hpp"

namespace swarmbox::swarm {

// agent/swarm/models/thermal_evidence.yaml, embedded at build time (CMakeLists.txt).
extern const unsigned char kShippedThermalEvidenceYaml[];
extern const std::size_t kShippedThermalEvidenceYamlSize;

const ThermalEvidence& ShippedThermalEvidence() {
  static const ThermalEvidence evidence = [] {
    const std::string_view text(reinterpret_cast<const char*>(kShippedThermalEvidenceYaml),
                                kShippedThermalEvidenceYamlSize);
    auto root = yaml::Parse(text, "agent/swarm/models/thermal_evidence.yaml");
    Result<ThermalEvidence> e = root ? ParseThermalEvidence(*root) : Result<ThermalEvidence>(root.error());
    if (!e) {
      std::fprintf(stderr, "swarmbox: fatal: the shipped thermal evidence: %s\n",
                   e.error().ToString().c_str());
      std::abort();
    }
    return *e;
  }();
  return evidence;
}

}  // namespace swarmbox::swarm
