#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>

#include "swarmbox/swarm/thermal_evidence.hpp"

namespace swarmbox::swarm {

// agent/swarm/models/thermal_evidence.yaml, embedded at build time (CMakeLists.txt).
extern const unsigned char kShippedThermalEvidenceYaml[];
extern const std::size_t kShippedThermalEvidenceYamlSize;
// agent/swarm/models/thermal_cnn.onnx, likewise.
extern const unsigned char kShippedThermalCnnOnnx[];
extern const std::size_t kShippedThermalCnnOnnxSize;

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
    if (e->cnn_weight > 0) {
      if (e->cnn_model != "thermal_cnn.onnx") {
        std::fprintf(
            stderr,
            "swarmbox: fatal: the shipped thermal evidence names %s, not the compiled-in thermal_cnn.onnx\n",
            e->cnn_model.c_str());
        std::abort();
      }
      e->cnn_onnx = std::make_shared<const std::string>(reinterpret_cast<const char*>(kShippedThermalCnnOnnx),
                                                        kShippedThermalCnnOnnxSize);
    }
    return *e;
  }();
  return evidence;
}

}  // namespace swarmbox::swarm
