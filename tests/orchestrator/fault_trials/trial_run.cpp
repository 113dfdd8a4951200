#include "trial_run.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <optional>
#include <sstream>

#include "program_images.hpp"
#include "support/child_process.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/dsl/plugin.hpp"
#include "swarmbox/dsl/trial_loader.hpp"
#include "swarmbox/runner/clock.hpp"
#include "swarmbox/runner/fault_image.hpp"
#include "swarmbox/runner/naming.hpp"
#include "swarmbox/runner/plan.hpp"

namespace swarmbox::fault_trials {
namespace {

namespace fs = std::filesystem;

struct BuiltImages {
  runner::Images trial;
  std::string faults;
};

// The images, built (or found by content hash) once per process.
Result<BuiltImages> Images(docker::DockerApi& api, std::ostream* progress) {
  static std::mutex mu;
  static std::optional<BuiltImages> cached;
  std::lock_guard<std::mutex> lk(mu);
  if (cached) return *cached;
  auto say = [progress](std::string_view line) {
    if (progress != nullptr) *progress << "  " << line << std::endl;
  };
  auto trial = cli::EnsureTrialImages(
      api, cli::ProgramPaths{.physics_bin = SWARMBOX_PHYSICS_BIN, .agent_bin = SWARMBOX_AGENT_BIN},
      say);
  if (!trial) return trial.error();
  auto faults = runner::EnsureFaultsImage(api, SWARMBOX_NETEMD_BIN, say);
  if (!faults) return faults.error();
  cached = BuiltImages{*trial, *faults};
  return *cached;
}

// RunTrialSpec (runner.cpp) with one addition: extra agent arguments in the planned tree.
Result<runner::RunOutcome> RunWithExtraArgs(const dsl::TrialSpec& spec, docker::DockerApi& api,
                                            const runner::RunOptions& options,
                                            const std::vector<std::pair<std::string, std::string>>& extra_flags) {
  const std::string trials_dir = fs::absolute(spec.trials_dir).lexically_normal().string();
  runner::TrialInfo info;
  info.name = spec.name;
  info.seed = spec.seed;
  info.resolved_yaml = yaml::Emit(spec.document.is_null() ? dsl::ToDocument(spec) : spec.document);
  info.world_file = (fs::path(trials_dir) / spec.world).string();
  for (const dsl::DroneSpec& d : spec.drones) info.drones.push_back(d.name);
  info.mesh = spec.mesh;
  info.faults = spec.faults;
  runner::Planner planner = [&](const std::string& run_id, const runner::TrialSubnets& subnets)
      -> Result<std::unique_ptr<dsl::Trial>> {
    runner::PlanOptions p;
    p.run_id = run_id;
    p.trial_id = options.trial_id;
    p.images = options.images;
    p.faults_image = runner::NeedsFaultSidecars(spec) ? options.faults_image : std::string();
    p.subnets = subnets;
    p.trials_dir = trials_dir;
    auto tree = runner::PlanTrial(spec, p);
    if (!tree) return tree;
    for (const dsl::DroneSpec& d : spec.drones) {
      dsl::Component* c = (*tree)->Find(d.name);
      auto* plugin = dynamic_cast<dsl::Plugin*>(c);
      if (plugin == nullptr) {
        return Error(ErrorCode::kInternal, "the planned tree has no agent plugin '" + d.name + "'");
      }
      std::vector<std::string>& argv = plugin->mutable_spec().argv;
      for (const auto& [flag, value] : extra_flags) {
        if (std::find(argv.begin(), argv.end(), flag) != argv.end()) continue;
        argv.push_back(flag);
        argv.push_back(value);
      }
    }
    return tree;
  };
  runner::SteadyClock clock;
  return runner::RunTrial(info, planner, api, clock, options);
}

}  // namespace

Result<std::unique_ptr<docker::DockerApi>> ConnectDocker() {
  auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
  if (!client) return client.error().Context("the fault trials need a Docker engine");
  return std::unique_ptr<docker::DockerApi>(std::move(*client));
}

Result<dsl::TrialSpec> LoadFaultTrial(const std::string& name, const std::vector<std::string>& sets) {
  dsl::LoadOptions opts;
  // These trials are judged on the netem model's figures through its sidecars (RunWithExtraArgs).
  opts.overrides = {"radio.model=netem"};
  opts.overrides.insert(opts.overrides.end(), sets.begin(), sets.end());
  return dsl::LoadTrial(std::string(SWARMBOX_SOURCE_DIR) + "/trials/faults/" + name, opts);
}

Result<TrialRun> RunFaultTrial(docker::DockerApi& api, const dsl::TrialSpec& spec,
                               const TrialRunConfig& config) {
  auto images = Images(api, config.progress);
  if (!images) return images.error().Context("building the trial images");
  runner::RunOptions options;
  options.out_dir = config.out_dir;
  options.run_id = runner::NewRunId();
  options.images = images->trial;
  options.faults_image = images->faults;
  options.progress = config.progress;
  auto outcome = RunWithExtraArgs(spec, api, options, config.extra_agent_flags);
  // Whatever the runner did, sweep the run's label (containers, networks) once more.
  docker::LabelSelector run;
  run.equals[std::string(docker::kLabelRun)] = options.run_id;
  auto swept = docker::RemoveLabelled(api, run, /*include_images=*/false);
  if (!outcome) return outcome.error();
  if (!swept) return swept.error().Context("removing what run " + options.run_id + " left");
  TrialRun out;
  out.outcome = std::move(*outcome);
  auto events = ReadEvents(out.outcome.trial_dir + "/events.jsonl");
  if (!events) return events.error();
  out.events = std::move(*events);
  return out;
}

bool AgentHasFlag(const std::string& flag) {
  auto help = swarmbox::testing::RunToEnd({SWARMBOX_AGENT_BIN, "--help"}, std::chrono::seconds(60), "/tmp");
  return help && help->out.find(flag) != std::string::npos;
}

}  // namespace swarmbox::fault_trials
