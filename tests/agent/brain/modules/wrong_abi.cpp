// Test library (brain_loader_test): exports the loader's two functions as a library built
// against another brain ABI would (its version is this SwarmBox's plus one).
#include "swarmbox/brain/brain.hpp"

extern "C" int swarmbox_brain_abi_version() { return swarmbox::brain::kAbiVersion + 1; }

extern "C" const std::vector<swarmbox::brain::Registration>* swarmbox_brain_registry() {
  static const std::vector<swarmbox::brain::Registration> none;
  return &none;
}
