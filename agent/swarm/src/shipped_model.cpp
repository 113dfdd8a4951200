// The detector models compiled into the binary: agent/swarm/models/victim_detector.yml.gz and the
// close-look model victim_detector_close.yml.gz, embedded
// by the assembler (.incbin) so that the agent image (a host binary and its libraries, see
// orchestrator/images) carries the model it was built with and needs no data file.
#include <mutex>

#include "swarmbox/swarm/victim_detector.hpp"
#include "swarmbox/swarm/victim_detector_model.hpp"

#if !defined(SWARMBOX_DETECTOR_MODEL_GZ) || !defined(SWARMBOX_DETECTOR_CLOSE_MODEL_GZ)
#error "SWARMBOX_DETECTOR_MODEL_GZ and SWARMBOX_DETECTOR_CLOSE_MODEL_GZ must name the models (CMakeLists.txt)"
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
        ".balign 16\n"
        ".global swarmbox_detector_close_model_gz\n"
        "swarmbox_detector_close_model_gz:\n"
        ".incbin \"" SWARMBOX_DETECTOR_CLOSE_MODEL_GZ "\"\n"
        ".global swarmbox_detector_close_model_gz_end\n"
        "swarmbox_detector_close_model_gz_end:\n"
        ".byte 0\n"
        ".previous\n"
        "# model sha256 " SWARMBOX_DETECTOR_MODEL_SHA256 " close " SWARMBOX_DETECTOR_CLOSE_MODEL_SHA256 "\n");

extern "C" const unsigned char swarmbox_detector_model_gz[];
extern "C" const unsigned char swarmbox_detector_model_gz_end[];
extern "C" const unsigned char swarmbox_detector_close_model_gz[];
extern "C" const unsigned char swarmbox_detector_close_model_gz_end[];

namespace swarmbox::swarm {
namespace {

std::shared_ptr<const VictimDetectorModel> LoadCompiledIn(const unsigned char* begin,
                                                          const unsigned char* end) {
  Result<std::string> text = GunzipText(begin, static_cast<std::size_t>(end - begin));
  SWARMBOX_CHECK(text.ok());
  Result<std::shared_ptr<const VictimDetectorModel>> m = LoadDetectorModelFromText(*text);
  SWARMBOX_CHECK(m.ok());
  return *m;
}

}  // namespace

std::shared_ptr<const VictimDetectorModel> ShippedDetectorModel() {
  static std::once_flag once;
  static std::shared_ptr<const VictimDetectorModel> model;
  std::call_once(once, [] { model = LoadCompiledIn(swarmbox_detector_model_gz, swarmbox_detector_model_gz_end); });
  return model;
}

std::shared_ptr<const VictimDetectorModel> ShippedCloseDetectorModel() {
  static std::once_flag once;
  static std::shared_ptr<const VictimDetectorModel> model;
  std::call_once(once, [] {
    model = LoadCompiledIn(swarmbox_detector_close_model_gz, swarmbox_detector_close_model_gz_end);
  });
  return model;
}

VictimDetector::VictimDetector(const VictimDetectorParams& params) : VictimDetector(ShippedDetectorModel(), params) {}

}  // namespace swarmbox::swarm
