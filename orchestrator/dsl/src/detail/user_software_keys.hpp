// The loader's decoders of `drones[].brain` and `components:` (user_software.hpp), one function per
// section. Errors are kInvalidArgument with where = "file:line:col" of the offending key.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/dsl/trial_spec.hpp"
#include "swarmbox/dsl/user_software.hpp"

namespace swarmbox::dsl::detail {

struct SoftwareContext {
  std::string base_dir;     // relative paths resolve against it (the trial file's folder)
  bool check_files = true;  // probe the referenced files (kind and existence)
  std::function<FileKind(const std::string& path)> file_kind;  // the probe
};

// One drone's `brain:` (a scalar `builtin` or a mapping).
Result<BrainSpec> DecodeBrain(const yaml::Node& node, const SoftwareContext& context);

// The `components:` list, checked against the trial decoded so far (drone names, radio model).
Result<std::vector<UserComponentSpec>> DecodeComponents(const yaml::Node& node, const TrialSpec& spec,
                                                        const SoftwareContext& context);

}  // namespace swarmbox::dsl::detail
