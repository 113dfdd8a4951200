// swarmbox-bench experiment: throughput of experiments on this machine, and where the wall time
// goes. Runs trials/experiments/hover_grid.yaml (short plan-hover trials of the real physics
// server and agent at rtf 0) on the local engine and prints one logfmt line:
//
//   suite=experiment scenario=hover_grid slots=1 trials=8 wall_s=... trials_per_hour=...
//     launch_s_mean=... sim_s_mean=... teardown_s_mean=... between_s_mean=... orchestration_share=...
//
// Per trial, from its events.jsonl (wall seconds since the runner started the trial):
//   launch    0 -> the physics server's event=ready (networks, containers, images checked, start)
//   sim       ready -> the orchestrator's shutdown record (the trial's verdict)
//   teardown  shutdown -> the trial's end (stop, logs and truth.csv collected, removal, outputs)
// and between = experiment wall x slots - the sum of the trials' wall times (scheduling, commits,
// report). orchestration_share = (launch + teardown + between) / (wall x slots).
// Options: --slots=N (default 1), --repetitions=N (default: the file's), --experiment=FILE (another
// experiment, e.g. trials/experiments/radio.yaml), --filter=PATTERN, --rtf=X (physics.rtf of every
// trial), --quick (1 repetition, codes
// with the first factor at level a: 2 trials of hover_grid). Fails (exit 1) when no engine answers
// or a trial has no result.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include "bench.hpp"
#include "program_images.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/experiment/experiment_runner.hpp"
#include "swarmbox/hosts/host.hpp"
#include "swarmbox/report/trial_record.hpp"
#include "swarmbox/runner/naming.hpp"

namespace {

namespace fs = std::filesystem;
using namespace swarmbox;

struct Phases {
  double launch_s = 0, sim_s = 0, teardown_s = 0, wall_s = 0;
  bool ok = false;
};

Phases ReadPhases(const fs::path& trial_dir, double wall_s) {
  Phases p;
  p.wall_s = wall_s;
  std::ifstream in(trial_dir / "events.jsonl");
  std::optional<double> ready, shutdown;
  for (std::string line; std::getline(in, line);) {
    auto j = yaml::Parse(line, "events.jsonl");
    if (!j || !j->is_mapping()) continue;
    const yaml::Node* ev = j->Find("event");
    const yaml::Node* comp = j->Find("component");
    const yaml::Node* w = j->Find("wall_s");
    if (ev == nullptr || comp == nullptr || w == nullptr) continue;
    auto t = yaml::ScalarAsDouble(w->scalar());
    if (!t) continue;
    if (!ready && ev->scalar() == "ready" && comp->scalar() == "physics") ready = t;
    if (ev->scalar() == "shutdown" && comp->scalar() == "orchestrator") shutdown = t;
  }
  if (ready && shutdown && *shutdown >= *ready) {
    p.launch_s = *ready;
    p.sim_s = *shutdown - *ready;
    p.teardown_s = wall_s - *shutdown;
    p.ok = true;
  }
  return p;
}

int RunExperimentBench(const bench::Args& args) {
  const int slots = static_cast<int>(args.GetInt("slots", 1));
  const std::string file = args.Get(
      "experiment", std::string(SWARMBOX_EXP_SOURCE_DIR) + "/trials/experiments/hover_grid.yaml");
  auto spec = experiment::LoadExperiment(file);
  if (!spec) {
    std::cerr << spec.error().ToString() << "\n";
    return 1;
  }
  spec->repetitions = static_cast<int>(args.GetInt("repetitions", args.quick ? 1 : spec->repetitions));
  if (args.quick) spec->filter = {std::string("a") + std::string(spec->factors.size() - 1, '?')};
  if (const std::string f = args.Get("filter", ""); !f.empty()) spec->filter = {f};
  if (const std::string rtf = args.Get("rtf", ""); !rtf.empty()) spec->set.push_back("physics.rtf=" + rtf);
  auto plan = experiment::PlanExperiment(*spec);
  if (!plan) {
    std::cerr << plan.error().ToString() << "\n";
    return 1;
  }
  auto host_spec = hosts::ParseHostSpec("local?slots=" + std::to_string(slots));
  if (!host_spec) {
    std::cerr << host_spec.error().ToString() << "\n";
    return 1;
  }
  const std::string run_id = runner::NewRunId();
  const fs::path out = fs::temp_directory_path() / ("swarmbox-bench-exp-" + run_id);
  auto host = hosts::ConnectHost(*host_spec, (out / "sock").string());
  if (!host) {
    std::cerr << "experiment bench: " << host.error().ToString() << "\n";
    return 1;
  }
  cli::ProgramPaths programs{SWARMBOX_EXP_PHYSICS_BIN, SWARMBOX_EXP_AGENT_BIN};
  auto images = cli::EnsureTrialImages((*host)->api(), programs, [](std::string_view) {});
  if (!images) {
    std::cerr << "experiment bench: " << images.error().ToString() << "\n";
    return 1;
  }
  auto faults = experiment::EnsurePlanFaultsImage(*plan, (*host)->api(), [](std::string_view) {});
  if (!faults) {
    std::cerr << "experiment bench: " << faults.error().ToString() << "\n";
    return 1;
  }
  hosts::Host* h = host->get();
  std::vector<experiment::PoolHost> pool = {
      {h->name(), h->slots(), &h->api(), [h] { return h->Check(); }, *images, *faults}};
  experiment::ExperimentOptions o;
  o.out_dir = (out / "exp").string();
  o.run_id = run_id;
  const auto t0 = std::chrono::steady_clock::now();
  auto summary = experiment::RunExperiment(*plan, pool, o);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!summary) {
    std::cerr << "experiment bench: " << summary.error().ToString() << "\n";
    fs::remove_all(out);
    return 1;
  }
  std::vector<std::string> problems;
  auto records = report::ReadExperimentFolder(o.out_dir, &problems);
  double launch = 0, sim = 0, teardown = 0, trial_wall = 0;
  std::size_t n = 0;
  std::map<std::string, int> outcomes;
  for (const auto& r : records) {
    outcomes[r.outcome] += 1;
    Phases p = ReadPhases(fs::path(o.out_dir) / r.folder, r.wall_s.value_or(0));
    if (!p.ok) continue;
    launch += p.launch_s;
    sim += p.sim_s;
    teardown += p.teardown_s;
    trial_wall += p.wall_s;
    ++n;
  }
  fs::remove_all(out);
  if (n == 0 || records.size() != plan->trials.size()) {
    std::cerr << "experiment bench: " << records.size() << "/" << plan->trials.size()
              << " trials have results, " << n << " with phases\n";
    return 1;
  }
  const double capacity = wall * slots;
  const double between = std::max(0.0, capacity - trial_wall);
  const double dn = static_cast<double>(n);
  std::printf(
      "suite=experiment scenario=%s slots=%d trials=%zu success=%d wall_s=%.1f "
      "trials_per_hour=%.0f launch_s_mean=%.2f sim_s_mean=%.2f teardown_s_mean=%.2f "
      "between_s_mean=%.2f orchestration_share=%.3f\n",
      spec->name.c_str(), slots, records.size(), outcomes["success"], wall, static_cast<double>(records.size()) / wall * 3600.0,
      launch / dn, sim / dn, teardown / dn, between / dn, (launch + teardown + between) / capacity);
  return 0;
}

}  // namespace

SWARMBOX_BENCH_SUITE(experiment,
                     "trials per hour of a short plan-hover experiment at rtf 0 on the local engine, "
                     "and the share of wall time spent in orchestration",
                     RunExperimentBench);
