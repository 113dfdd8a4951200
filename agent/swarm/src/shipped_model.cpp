// The detector model compiled into the binary: agent/swarm/models/victim_detector.yml.gz, embedded
// by the assembler (.incbin) so that the agent image (a host binary and its libraries, see
// orchestrator/images) carries the model it was built with and needs no data file.
#include <mutex>

#include "swarmbox/swarm/victim_detector.hpp"
#include "swarmbox/swarm/victim_detector_model.hpp"

#ifndef SWARMBOX_DETECTOR_MODEL_GZ
#error "SWARMBOX_DETECTOR_MODEL_GZ must name the model file (agent/swarm/CMakeLists.txt)"
#endif

// SWARMBOX_DETECTOR_MODEL_SHA256 (the file's hash at configure time) makes the compiler cache see a
// new model as a new translation unit: .incbin reads the file behind the preprocessor's back.
__asm__(".section .rodata\n"
        ".balign 16\n"
        ".global swarmbox_detector_model_gz\n"
        "swarmbox_detector_model_gz:\n"
        ".incbin \"" SWARMBOX_DETECTOR_MODEL_GZ "\"\n"
        ".global swarmbox_detector_model_gz_end\n"
        "swarmbox_detector_model_gz_end:\n"
        ".byte 0\n"
        ".previous\n"
        "# model sha256 " SWARMBOX_DETECTOR_MODEL_SHA256 "\n");

extern "C" const unsigned char swarmbox_detector_model_gz[];
extern "C" const unsigned char swarmbox_detector_model_gz_end[];

namespace swarmbox::swarm {

std::shared_ptr<const VictimDetectorModel> ShippedDetectorModel() {
  static std::once_flag once;
  static std::shared_ptr<const VictimDetectorModel> model;
  std::call_once(once, [] {
    const auto size = static_cast<std::size_t>(swarmbox_detector_model_gz_end - swarmbox_detector_model_gz);
    Result<std::string> text = GunzipText(swarmbox_detector_model_gz, size);
    SWARMBOX_CHECK(text.ok());
    Result<std::shared_ptr<const VictimDetectorModel>> m = LoadDetectorModelFromText(*text);
    SWARMBOX_CHECK(m.ok());
    model = *m;
  });
  return model;
}

VictimDetector::VictimDetector(const VictimDetectorParams& params) : VictimDetector(ShippedDetectorModel(), params) {}

}  // namespace swarmbox::swarm
