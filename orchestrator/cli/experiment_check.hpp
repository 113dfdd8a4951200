// `swarmbox validate` on experiment files: telling an experiment from a trial, and pointing an
// error of one of its trials back at the experiment's own line.
//
// A trial of an experiment is the base trial with overrides (`set:`, the factor levels, seed and
// name; experiment_spec.hpp) applied as `--set` would be, so dsl::LoadTrial reports a bad level
// value at "--set network.mesh.loss:1:1". LocateInExperiment finds the node of the experiment
// file that override came from (the level of this trial's code, or the `set:` entry) and moves
// the error there: "trials/experiments/radio.yaml:14:22: ...". Errors in the base trial's own
// text already point at the base trial's line and stay as they are. Pure: no I/O.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/experiment/experiment_spec.hpp"

namespace swarmbox::cli {

// Whether a parsed YAML document is an experiment (it has `factors:` or `base:`, and no `world:`)
// rather than a trial.
bool LooksLikeExperiment(const yaml::Node& document);

// The override key an error of dsl::LoadTrial came from ("--set a.b:1:3" or "--set a.b=v" ->
// "a.b"); nullopt when the error is not about an override.
std::optional<std::string> OverrideKeyOf(const Error& error);

// Where in the experiment document the value of override `key` of `trial` is written: the level
// of the trial's code (last factor first: later overrides win), else the `set:` entry, else the
// `seed:` / `name:` entry; nullopt when the experiment does not set it (a validate --set).
std::optional<yaml::Mark> LocateOverride(const yaml::Node& experiment_document,
                                         const experiment::PlannedTrial& trial,
                                         std::string_view key);

// `error` of loading `trial` moved to the experiment's line when it came from an override the
// experiment sets, with the trial named: "<file:line:col>: <message> (trial <id>, key <key>)".
// Otherwise the error with the trial named.
Error LocateInExperiment(const Error& error, const yaml::Node& experiment_document,
                         const experiment::PlannedTrial& trial);

}  // namespace swarmbox::cli
