// swarmbox validate FILE... [--set key=value ...]
#include <iostream>

#include "commands.hpp"
#include "load_trial.hpp"

namespace swarmbox::cli {

int ValidateCommand(const ValidateArgs& args) {
  int bad = 0;
  for (const std::string& file : args.files) {
    auto spec = LoadTrialOrPrintError(file, args.sets);
    if (!spec) {
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
