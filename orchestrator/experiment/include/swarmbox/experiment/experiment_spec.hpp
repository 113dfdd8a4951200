// ExperimentSpec: what an experiment file says, and its expansion into trials (pure, no I/O
// beyond reading the file in LoadExperiment).
//
//   name: radio                        # [a-z0-9][a-z0-9_.-]*: trial ids are <name>-<code>-r<rep>
//   base: ../sar_search.yaml           # the base trial, relative to this file
//   set: {physics.rtf: 0}              # overrides for every trial (`swarmbox run --set` keys)
//   factors:                           # in code order: code "ab" = first factor a, second b
//     - name: loss                     # a results.csv column
//       key: network.mesh.loss         # the trial key each level sets
//       levels: {a: 0, b: 0.05, c: 0.2}
//     - name: scouts                   # several keys: each level is a list, one value per key
//       keys: [drones.scout.count, world_size_m]
//       levels: {a: [5, [150, 150]], b: [100, [600, 600]]}   # label: the first value (5, 100)
//     - name: swarm                    # no key: each level is a mapping of overrides
//       levels:
//         a: {drones: [{name: scout_1, airframe: x500, pose: [0, 0, 0]}]}
//         b: {drones: [...]}
//       labels: {a: one, b: three}     # optional names for the levels (default: the value, or
//                                      # the letter for override levels)
//   codes: [aa, cb]                    # optional: explicit level codes (default: full factorial)
//   filter: ["a?", "?b"]               # optional: run only codes matching one of these (? = any)
//   repetitions: 3                     # default 1
//   seed: 1000                         # base of the derived seeds (default: the base trial's)
//   seeds: paired                      # paired (default): repetition r has the same seed at every
//                                      # code (common random numbers); independent: per trial
//   hosts: [local?slots=2]             # optional default pool (`--hosts` replaces it)
//
// Every trial is the base file with overrides, applied by the same machinery as `swarmbox run
// --set` (dsl::ApplyOverride), in this order: `set`, the factor levels (in factor order), then
// seed=<derived> and name=<trial id>. Errors are `file:line:col: message`.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::experiment {

struct Level {
  char code = 'a';
  std::string label;           // for results.csv and the report
  std::vector<std::string> overrides;  // "key.path=<value as JSON>"
};

struct Factor {
  std::string name;
  std::string key;  // "" when each level is a mapping of overrides, or with `keys`
  std::vector<std::string> keys;  // `keys:` (each level a list of as many values); empty = `key`
  std::vector<Level> levels;  // sorted by code
  const Level* FindLevel(char code) const;
};

enum class SeedMode { kPaired, kIndependent };

struct ExperimentSpec {
  std::string name;
  std::string file;       // the experiment file ("" when built in code)
  std::string base_trial; // path of the base trial file (resolved against the experiment file)
  std::vector<std::string> set;  // overrides for every trial
  std::vector<Factor> factors;
  std::vector<std::string> codes;   // explicit; empty = full factorial
  std::vector<std::string> filter;  // patterns over codes; empty = all
  int repetitions = 1;
  std::uint64_t seed = 0;
  bool seed_given = false;  // false: the base trial's seed is used (LoadExperiment fills it in)
  SeedMode seeds = SeedMode::kPaired;
  std::vector<std::string> hosts;
};

struct PlannedTrial {
  std::string id;    // <name>-<code>-r<rep>; also the trial's name and its folder
  std::string code;  // one letter per factor
  std::vector<std::string> levels;  // the level label per factor
  int repetition = 1;  // 1-based
  std::uint64_t seed = 0;
  std::vector<std::string> overrides;  // everything to apply to the base trial, in order
};

// Parses an experiment document (the base trial is not read here; see LoadExperiment).
Result<ExperimentSpec> ParseExperiment(const yaml::Node& document, std::string_view file);
// Reads the file, parses it, resolves `base` against the file's folder and, when no `seed:` is
// given, takes the base trial's top-level seed.
Result<ExperimentSpec> LoadExperiment(const std::string& path);

// All codes in factorial order (first factor slowest): aa, ab, ba, bb...
std::vector<std::string> FactorialCodes(const std::vector<Factor>& factors);
// Whether `code` matches a pattern ('?' or '*' matches any level at that position).
bool CodeMatches(std::string_view code, std::string_view pattern);
// The seed of repetition `rep` (1-based) of `code` (pure; SplitMix64 of the inputs, < 2^31).
std::uint64_t DeriveSeed(std::uint64_t base, SeedMode mode, std::string_view code, int rep);
// Checks a code against the factors (length, letters): kInvalidArgument saying what is wrong.
Status CheckCode(const std::vector<Factor>& factors, std::string_view code);

// The trials of an experiment, in run order (code, then repetition). Errors: a bad explicit code,
// a filter pattern of the wrong length, a filter that leaves nothing, duplicate codes.
Result<std::vector<PlannedTrial>> ExpandTrials(const ExperimentSpec& spec);

// The trial id for a code and repetition: <name>-<code>-r<rep>.
std::string TrialId(std::string_view name, std::string_view code, int rep);

}  // namespace swarmbox::experiment
