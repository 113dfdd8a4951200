#include "load_trial.hpp"

#include <iostream>

#include "swarmbox/dsl/trial_loader.hpp"

namespace swarmbox::cli {

Result<dsl::TrialSpec> LoadTrialOrPrintError(const std::string& file, const std::vector<std::string>& sets) {
  dsl::LoadOptions load;
  load.overrides = sets;
  auto spec = dsl::LoadTrial(file, load);
  if (!spec) std::cerr << spec.error().ToString() << "\n";
  return spec;
}

}  // namespace swarmbox::cli
