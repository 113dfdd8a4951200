// swarmbox validate FILE... [--set key=value ...] [--json]
//
// Each FILE is a trial or an experiment (experiment_check.hpp tells them apart). An experiment is
// checked as `swarmbox experiment` would load it, then every trial it expands to is loaded with
// its overrides (and the --set ones after the experiment's `set:`); an error from an override is
// reported at the experiment's line, one that is in the base trial at the base trial's line, each
// once however many trials share it. Errors go to stderr as file:line:col: message (also into the
// --json summary); exit 2 when any file is bad, after checking them all.
#include <iostream>
#include <map>

#include "commands.hpp"
#include "experiment_check.hpp"
#include "json_out.hpp"
#include "load_trial.hpp"
#include "swarmbox/dsl/trial_loader.hpp"
#include "swarmbox/runner/derived_world.hpp"

namespace swarmbox::cli {

namespace {

struct FileReport {
  std::string file;
  std::string kind;     // "trial" or "experiment"
  std::string name;     // the trial's or experiment's name ("" when it did not load)
  std::string summary;  // the "ok (...)" text
  std::size_t trials = 0;  // experiment: trials checked
  std::vector<std::string> errors;
};

// "trial NAME, 101 drones (scout x100), 3 end conditions, timeout 600s": groups counted expanded.
std::string TrialSummary(const dsl::TrialSpec& spec) {
  std::string groups;
  for (const dsl::DroneGroup& g : spec.groups) {
    groups += (groups.empty() ? " (" : ", ") + g.name + " x" + std::to_string(g.count);
  }
  if (!groups.empty()) groups += ")";
  return "trial " + spec.name + ", " + std::to_string(spec.drones.size()) + " drones" + groups + ", " +
         std::to_string(spec.end.size()) + " end conditions, timeout " + spec.timeout.sim.ToString();
}

// The user's software, when there is some: ", brains scout_1 library, scout_2 program, components
// probe (program)".
std::string UserSoftwareSummary(const dsl::TrialSpec& spec) {
  std::string brains;
  for (const dsl::DroneSpec& d : spec.drones) {
    if (d.brain.kind == dsl::BrainKind::kBuiltin) continue;
    brains += (brains.empty() ? "" : ", ") + d.name + " " + std::string(dsl::BrainKindName(d.brain.kind));
  }
  std::string components;
  for (const dsl::UserComponentSpec& c : spec.components) {
    components += (components.empty() ? "" : ", ") + c.name + " (" + std::string(dsl::ComponentSourceName(c.source)) + ")";
  }
  std::string summary;
  if (!brains.empty()) summary += ", brains " + brains;
  if (!components.empty()) summary += ", components " + components;
  return summary;
}

// ", world KIND seed N (V victims, O obstacles, D distractors)".
std::string WorldSummary(const worlds::GenerateSpec& g, std::uint64_t trial_seed) {
  return ", world " + std::string(worlds::KindName(g.kind)) + " seed " +
         std::to_string(worlds::WorldSeed(g, trial_seed)) + " (" + std::to_string(g.victims) + " victims, " +
         std::to_string(g.obstacles) + " obstacles, " + std::to_string(g.distractors) + " distractors)";
}

FileReport ValidateTrial(const std::string& file, const std::vector<std::string>& sets) {
  FileReport r{file, "trial", "", "", 1, {}};
  auto spec = LoadTrialOrPrintError(file, sets);
  if (!spec) {
    r.errors.push_back(spec.error().ToString());
    return r;
  }
  r.name = spec->name;
  r.summary = TrialSummary(*spec) + UserSoftwareSummary(*spec);
  // A generated world is generated here as the runner would (it can fail: an area too small).
  if (spec->world_generate) {
    auto world = runner::DerivedWorldText(*spec, spec->trials_dir);
    if (!world) {
      r.errors.push_back(file + ": world: " + world.error().ToString());
      std::cerr << r.errors.back() << "\n";  // as LoadTrialOrPrintError does for the trial's errors
      return r;
    }
    r.summary += WorldSummary(*spec->world_generate, spec->seed);
  }
  return r;
}

// Every expanded trial loaded: one error per distinct error (the first trial that has it named,
// located in the experiment), with how many trials have it.
std::vector<Error> TrialLoadErrors(const experiment::ExperimentSpec& spec, const yaml::Node& document,
                                   const std::vector<experiment::PlannedTrial>& trials) {
  std::vector<std::pair<std::string, Error>> order;  // the error as LoadTrial gave it, located
  std::map<std::string, int> count;
  for (const experiment::PlannedTrial& t : trials) {
    dsl::LoadOptions load;
    load.overrides = t.overrides;
    auto trial = dsl::LoadTrial(spec.base_trial, load);
    if (trial) continue;
    const std::string key = trial.error().ToString();
    if (count[key]++ == 0) order.emplace_back(key, LocateInExperiment(trial.error(), document, t));
  }
  std::vector<Error> errors;
  for (const auto& [key, located] : order) {
    const int others = count[key] - 1;
    errors.push_back(others == 0 ? located
                                 : Error(located.code(),
                                         located.message() + " (and " + std::to_string(others) +
                                             (others == 1 ? " more trial)" : " more trials)"),
                                         located.where()));
  }
  return errors;
}

FileReport ValidateExperiment(const std::string& file, const yaml::Node& document,
                              const std::vector<std::string>& sets) {
  FileReport r{file, "experiment", "", "", 0, {}};
  auto fail = [&](const Error& e) {
    std::cerr << e.ToString() << "\n";
    r.errors.push_back(e.ToString());
  };
  auto spec = experiment::LoadExperiment(file);
  if (!spec) {
    fail(spec.error());
    return r;
  }
  r.name = spec->name;
  spec->set.insert(spec->set.end(), sets.begin(), sets.end());
  auto trials = experiment::ExpandTrials(*spec);
  if (!trials) {
    fail(trials.error());
    return r;
  }
  r.trials = trials->size();
  for (const Error& e : TrialLoadErrors(*spec, document, *trials)) fail(e);
  if (r.errors.empty()) {
    r.summary = "experiment " + spec->name + ", " + std::to_string(trials->size()) + " trials of " +
                spec->base_trial + ", " + std::to_string(spec->factors.size()) + " factors";
  }
  return r;
}

}  // namespace

int ValidateCommand(const ValidateArgs& args) {
  std::vector<FileReport> reports;
  for (const std::string& file : args.files) {
    auto document = yaml::ParseFile(file);
    if (document && LooksLikeExperiment(*document)) {
      reports.push_back(ValidateExperiment(file, *document, args.sets));
    } else {
      reports.push_back(ValidateTrial(file, args.sets));  // reports an unreadable file too
    }
  }
  std::size_t bad = 0;
  for (const FileReport& r : reports) bad += r.errors.empty() ? 0u : 1u;
  if (args.json) {
    yaml::Node o = yaml::Node::Mapping();
    o.Set("ok", json::Bool(bad == 0));
    yaml::Node files = yaml::Node::Sequence();
    for (const FileReport& r : reports) {
      yaml::Node f = yaml::Node::Mapping();
      f.Set("file", json::Str(r.file));
      f.Set("kind", json::Str(r.kind));
      f.Set("name", json::Str(r.name));
      f.Set("ok", json::Bool(r.errors.empty()));
      if (r.kind == "experiment") f.Set("trials", json::Int(static_cast<std::int64_t>(r.trials)));
      f.Set("errors", json::Strs(r.errors));
      files.Append(std::move(f));
    }
    o.Set("files", std::move(files));
    json::Print(o);
  } else {
    for (const FileReport& r : reports) {
      if (r.errors.empty()) std::cout << r.file << ": ok (" << r.summary << ")\n";
    }
  }
  return bad == 0 ? kExitOk : kExitUsage;
}

}  // namespace swarmbox::cli
