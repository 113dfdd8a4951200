// hover_experiment: an experiment written as a C++ program against the installed swarmbox library,
// the counterpart of trials/experiments/hover_grid.yaml (the README's experiment tutorial in YAML).
//
//   hover_experiment [--out DIR] [--slots N] [--filter PATTERN ...] [--trials-dir DIR]
//
// One x500 scout flies a built-in plan (take off, hover 1 s, land) as fast as the machine allows.
// Two factors, two levels each: the take-off altitude (2 m, 3 m) and the start position (the
// origin, 20 m north-east); two repetitions with paired seeds: 8 trials, run on the local Docker
// engine, `--slots` at a time. The output folder is what `swarmbox experiment` writes: one folder
// per trial (result.json, trial.yaml, logs, truth.csv, trajectories.png, ...), experiment.json,
// results.csv, report.html and plots/. `swarmbox report DIR` reads it like any other.
//
// The steps are those of `swarmbox experiment`, each a library call:
//   1. the base trial (dsl::TrialSpec's builder) and the experiment (experiment::ExperimentSpec);
//   2. the plan: every trial is the base trial with its overrides, loaded and checked before
//      anything runs (experiment::ExpandTrials, dsl::LoadTrialText);
//   3. the host: the local engine (hosts::ConnectHost) with the images of the installed programs
//      (images::FindProgram, images::EnsureImage);
//   4. experiment::RunExperiment, which runs the trials and writes results.csv and report.html.
//
// Exit codes as `swarmbox experiment`'s: 0 every trial has an outcome, 1 interrupted (Ctrl-C),
// 2 bad input, 3 trials left without a result (no engine, images failed).
#include <atomic>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/dsl/trial_loader.hpp"
#include "swarmbox/dsl/trial_spec.hpp"
#include "swarmbox/experiment/experiment_runner.hpp"
#include "swarmbox/experiment/experiment_spec.hpp"
#include "swarmbox/hosts/host.hpp"
#include "swarmbox/hosts/host_spec.hpp"
#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/find_program.hpp"
#include "swarmbox/images/standard_images.hpp"
#include "swarmbox/images/tag_cache.hpp"
#include "swarmbox/runner/naming.hpp"

namespace {

namespace fs = std::filesystem;
using swarmbox::Result;
using swarmbox::dsl::Duration;
using swarmbox::dsl::Outcome;
namespace dsl = swarmbox::dsl;
namespace experiment = swarmbox::experiment;
namespace yaml = swarmbox::yaml;

constexpr int kExitOk = 0, kExitInterrupted = 1, kExitUsage = 2, kExitInfrastructure = 3;

// The base trial: trials/smoke.yaml with hover_grid.yaml's `set:` (a flight plan, rtf 0).
dsl::TrialSpec BaseTrial() {
  return dsl::TrialSpec::Named("hover")
      .Seed(1)
      .World("worlds/open_field.yaml")
      .Rtf(0)  // as fast as the machine allows
      .Drone("scout_1", "x500", {0, 0, 0})
      .Mission({.kind = dsl::MissionKind::kPlan, .plan = "takeoff:2,hover:1,land"})
      .EndOn("event=plan_complete", Outcome::kSuccess)
      .EndOn("event=collision", Outcome::kFailure, "collision")
      .EndOn("event=crash", Outcome::kFailure, "crash")
      .Timeout(Duration::Seconds(60), Outcome::kTimeout, Duration::Minutes(4));
}

// A factor whose levels set one key of the trial: {label, value as JSON} per level, coded a, b, ...
// (what a factor with `key:`, `levels:` and `labels:` in an experiment file becomes).
experiment::Factor KeyFactor(std::string name, std::string key,
                             std::vector<std::pair<std::string, std::string>> label_json) {
  experiment::Factor f{std::move(name), std::move(key), /*keys=*/{}, /*levels=*/{}};
  char code = 'a';
  for (auto& [label, json] : label_json) {
    f.levels.push_back({code++, std::move(label), {f.key + "=" + json}});
  }
  return f;
}

// The experiment: hover_grid.yaml's factors, levels, repetitions and seed.
experiment::ExperimentSpec Experiment() {
  experiment::ExperimentSpec spec;
  spec.name = "hover";
  spec.base_trial = "BaseTrial() in examples/hover_experiment.cpp";  // recorded in experiment.json
  spec.factors = {
      KeyFactor("altitude", "mission.plan",
                {{"2m", yaml::JsonQuote("takeoff:2,hover:1,land")},
                 {"3m", yaml::JsonQuote("takeoff:3,hover:1,land")}}),
      KeyFactor("start", "drones.scout_1.pose", {{"origin", "[0,0,0]"}, {"ne20", "[20,20,0]"}}),
  };
  spec.repetitions = 2;
  spec.seed = 7;
  spec.seed_given = true;
  spec.seeds = experiment::SeedMode::kPaired;  // repetition r has one seed at every code
  return spec;
}

// Every trial of the experiment: the base trial's YAML with the trial's overrides (the factor
// levels, its seed and name), decoded and checked against the trials folder (worlds/, airframes/).
Result<experiment::ExperimentPlan> Plan(const experiment::ExperimentSpec& spec,
                                        const dsl::TrialSpec& base, const std::string& trials_dir) {
  experiment::ExperimentPlan plan;
  plan.spec = spec;
  auto trials = experiment::ExpandTrials(spec);
  if (!trials) return trials.error();
  plan.trials = std::move(*trials);
  const std::string base_yaml = yaml::Emit(dsl::ToDocument(base));
  for (const experiment::PlannedTrial& t : plan.trials) {
    dsl::LoadOptions load;
    load.overrides = t.overrides;
    load.trials_dir = trials_dir;
    auto trial = dsl::LoadTrialText(base_yaml, "hover_experiment.cpp", load);
    if (!trial) return trial.error().Context("trial " + t.id + " (code " + t.code + ")");
    plan.specs.emplace(t.id, std::move(*trial));
  }
  return plan;
}

// The images of the installed swarmbox-physics and swarmbox-agent on `api` (built when missing;
// $SWARMBOX_BIN_DIR, then the package's bin folder, then $PATH).
Result<swarmbox::runner::Images> EnsureImages(swarmbox::docker::DockerApi& api) {
  namespace images = swarmbox::images;
  const images::TagCache cache(images::DefaultTagCacheDir());
  auto progress = [](std::string_view line) { std::cerr << "  " << line << "\n"; };
  swarmbox::runner::Images out;
  for (const char* program : {"swarmbox-physics", "swarmbox-agent"}) {
    auto binary = images::FindProgram(program, "", {fs::path(SWARMBOX_BIN_DIR) / program},
                                      "install swarmbox (cmake --install) or set SWARMBOX_BIN_DIR");
    if (!binary) return binary.error();
    const bool physics = std::string_view(program) == "swarmbox-physics";
    auto image = images::EnsureImage(
        api, physics ? images::PhysicsImage(*binary) : images::AgentImage(*binary), progress,
        nullptr, &cache);
    if (!image) return image.error().Context(program);
    (physics ? out.physics : out.agent) = image->tag;
  }
  return out;
}

std::atomic<bool> g_interrupted{false};
extern "C" void OnInterrupt(int) { g_interrupted.store(true); }

// The command line.
struct Args {
  std::string out;  // empty: runs/<experiment>-<run id>
  std::string trials_dir = SWARMBOX_TRIALS_DIR;
  int slots = 2;
  std::vector<std::string> filter;
};

// Parses argv into `args`. An exit code when the program ends here: --help (0), bad usage (2).
std::optional<int> ParseArgs(int argc, char** argv, Args& args) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (i + 1 < argc && a == "--out") {
      args.out = argv[++i];
    } else if (i + 1 < argc && a == "--slots") {
      args.slots = std::atoi(argv[++i]);
    } else if (i + 1 < argc && a == "--filter") {
      args.filter.emplace_back(argv[++i]);
    } else if (i + 1 < argc && a == "--trials-dir") {
      args.trials_dir = argv[++i];
    } else {
      std::cerr << "usage: hover_experiment [--out DIR] [--slots N] [--filter PATTERN ...] "
                   "[--trials-dir DIR]\n";
      return a == "--help" ? kExitOk : kExitUsage;
    }
  }
  if (args.slots < 1) {
    std::cerr << "hover_experiment: --slots must be at least 1\n";
    return kExitUsage;
  }
  return std::nullopt;
}

// Says why the program stops ("hover_experiment: [what]reason") and gives its exit code.
int Fail(const swarmbox::Error& error, int exit_code, std::string_view what = {}) {
  std::cerr << "hover_experiment: " << what << error.ToString() << "\n";
  return exit_code;
}

// 4. Runs every trial on `pool`; results.csv and report.html are written at the end. The exit
// code (SIGINT/SIGTERM mark the run interrupted: 1).
int RunAndReport(const experiment::ExperimentPlan& plan, const std::vector<experiment::PoolHost>& pool,
                 const std::string& out, const std::string& run_id, const std::string& workdir) {
  std::signal(SIGINT, OnInterrupt);
  std::signal(SIGTERM, OnInterrupt);
  experiment::ExperimentOptions options;
  options.out_dir = out;
  options.run_id = run_id;
  options.interrupted = &g_interrupted;
  options.progress = &std::cerr;
  auto summary = experiment::RunExperiment(plan, pool, options);
  std::error_code ec;
  fs::remove_all(workdir, ec);
  if (!summary) return Fail(summary.error(), kExitInfrastructure);
  for (const std::string& p : summary->problems) std::cerr << "  note: " << p << "\n";
  std::cout << out << ": " << summary->committed << "/" << summary->total << " trials";
  for (const auto& [outcome, n] : summary->outcomes) std::cout << ", " << outcome << " " << n;
  std::cout << "; " << out << "/results.csv, " << out << "/report.html\n";
  if (g_interrupted.load()) return kExitInterrupted;
  return summary->committed == summary->total ? kExitOk : kExitInfrastructure;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (std::optional<int> exit_code = ParseArgs(argc, argv, args)) return *exit_code;

  // 1-2. The experiment, and every trial it expands to, checked before anything runs.
  experiment::ExperimentSpec spec = Experiment();
  spec.filter = args.filter;
  auto plan = Plan(spec, BaseTrial(), args.trials_dir);
  if (!plan) return Fail(plan.error(), kExitUsage);
  const std::string run_id = swarmbox::runner::NewRunId();
  const std::string out = args.out.empty() ? "runs/" + spec.name + "-" + run_id : args.out;
  if (auto checked = experiment::CheckOutFolder(*plan, out, /*resume=*/false); !checked) {
    return Fail(checked.error(), kExitUsage);
  }
  std::cerr << "hover_experiment: " << plan->trials.size() << " trials, run " << run_id << " -> "
            << out << "\n";

  // 3. The local engine and the images of the installed programs.
  auto host_spec = swarmbox::hosts::ParseHostSpec("local?slots=" + std::to_string(args.slots));
  if (!host_spec) return Fail(host_spec.error(), kExitUsage);
  const std::string workdir = (fs::temp_directory_path() / ("swarmbox-" + run_id)).string();
  auto host = swarmbox::hosts::ConnectHost(*host_spec, workdir);
  if (!host) return Fail(host.error(), kExitInfrastructure);
  auto images = EnsureImages((*host)->api());
  if (!images) return Fail(images.error(), kExitInfrastructure, "images: ");
  swarmbox::hosts::Host* h = host->get();
  // No trial of this experiment impairs the mesh: no fault sidecar image (see
  // experiment::EnsurePlanFaultsImage for experiments that do).
  const std::vector<experiment::PoolHost> pool = {
      {h->name(), h->slots(), &h->api(), [h] { return h->Check(); }, *images, ""}};
  return RunAndReport(*plan, pool, out, run_id, workdir);
}
