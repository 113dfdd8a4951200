// LoadTrial: a trial file (YAML) -> TrialSpec, strictly: unknown keys, wrong types, missing fields,
// bad values and bad references (an airframe or world file that does not exist, a fault naming a
// drone that is not there) are errors with where = "file:line:col".
//
//   LoadOptions opts;
//   opts.overrides = {"network.mesh.loss=0.1", "seed=7"};    // --set, applied before checking
//   auto spec = LoadTrial("trials/sar_search.yaml", opts);
//   if (!spec) { std::cerr << spec.error().ToString() << "\n"; return 2; }
//
// References resolve against the trials directory: `world: worlds/open_field.yaml` is
// <trials_dir>/worlds/open_field.yaml, `airframe: x500` is <trials_dir>/airframes/x500.yaml.
// trials_dir defaults to the nearest folder named `trials` that holds the trial file (so
// trials/faults/partition.yaml resolves against trials/), else the trial file's folder.
// Brain and component paths (`drones[].brain`, `components:`) resolve against the trial file's own
// folder and are checked (existence and kind: user_software.hpp) with check_references.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/dsl/trial_spec.hpp"

namespace swarmbox::dsl {

struct LoadOptions {
  std::vector<std::string> overrides;  // "key.path=value", applied in order
  std::string trials_dir;              // "" = DefaultTrialsDir(the trial file)
  // Whether a referenced file exists; default: std::filesystem. Tests pass a fake.
  std::function<bool(const std::string& path)> file_exists;
  bool check_references = true;
  // What a brain's or component's file is (user_software.hpp); default: ProbeFileKind.
  std::function<FileKind(const std::string& path)> file_kind;
  // Where brain and component paths resolve; "" = the trial file's folder (LoadTrialText sets it).
  std::string base_dir;
};

// The default trials directory of a trial file (see above).
std::string DefaultTrialsDir(std::string_view trial_file);

// Reads the file, applies overrides, decodes and checks it.
Result<TrialSpec> LoadTrial(const std::string& path, const LoadOptions& options = {});
// The same on text already in memory (`filename` is used in marks and to find trials_dir).
Result<TrialSpec> LoadTrialText(std::string_view text, std::string_view filename,
                                const LoadOptions& options = {});
// Decodes and checks a parsed document (overrides are not applied here).
Result<TrialSpec> DecodeTrial(const yaml::Node& document, const LoadOptions& options = {});

}  // namespace swarmbox::dsl
