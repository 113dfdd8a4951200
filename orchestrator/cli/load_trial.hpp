// The trial loading that `swarmbox run`, `compose` and `validate` share.
#pragma once

#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/dsl/trial_spec.hpp"

namespace swarmbox::cli {

// dsl::LoadTrial(file) with the --set overrides `sets` (key.path=value, in order). On failure
// the error (file:line:col: message) is already printed on stderr when this returns; the caller
// only decides the exit code.
Result<dsl::TrialSpec> LoadTrialOrPrintError(const std::string& file, const std::vector<std::string>& sets);

}  // namespace swarmbox::cli
