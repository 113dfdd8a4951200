// swarmbox validate FILE... [--set key=value ...]
#include <iostream>

#include "commands.hpp"
#include "swarmbox/dsl/trial_loader.hpp"

namespace swarmbox::cli {

int ValidateCommand(const ValidateArgs& args) {
  int bad = 0;
  for (const std::string& file : args.files) {
    dsl::LoadOptions load;
    load.overrides = args.sets;
    auto spec = dsl::LoadTrial(file, load);
    if (!spec) {
      std::cerr << spec.error().ToString() << "\n";
      ++bad;
      continue;
    }
    std::cout << file << ": ok (trial " << spec->name << ", " << spec->drones.size()
              << " drones, " << spec->end.size() << " end conditions, timeout "
              << spec->timeout.sim.ToString() << ")\n";
  }
  return bad == 0 ? kExitOk : kExitUsage;
}

}  // namespace swarmbox::cli
