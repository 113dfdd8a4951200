// Test library (brain_loader_test): the right brain ABI version, but built (it says) against
// another C++ standard library than the agent's, whose std::string and std::vector differ.
#include "swarmbox/brain/brain.hpp"

extern "C" int swarmbox_brain_abi_version() { return swarmbox::brain::kAbiVersion; }

extern "C" const char* swarmbox_brain_cxx_library() { return "libc++"; }

extern "C" const std::vector<swarmbox::brain::Registration>* swarmbox_brain_registry() {
  static const std::vector<swarmbox::brain::Registration> none;
  return &none;
}
