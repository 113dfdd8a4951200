// Test brain library (brain_loader_test): two SWARMBOX_BRAIN lines with one name.
#include "swarmbox/brain/brain.hpp"

namespace {

namespace sb = swarmbox::brain;

class Twin final : public sb::Brain {
 public:
  explicit Twin(const sb::Context& /*ctx*/) {}
  void Step(const sb::Input& /*in*/, sb::Output& /*out*/) override {}
};

}  // namespace

SWARMBOX_BRAIN("twin", Twin)
SWARMBOX_BRAIN("twin", Twin)
