// swarmbox gc [--run ID]: remove what killed runs left behind, by label.
//
// Without --run: every run id labelled on the engine's containers and networks, except the runs
// still alive on this machine (run_lock.hpp: their swarmbox holds the run's lock), which are
// named and left alone: gc must never pull a running trial's network from under it. With
// --run ID: that run, alive or not (the user said which).
#include <iostream>
#include <set>

#include "commands.hpp"
#include "run_lock.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"

namespace swarmbox::cli {

namespace {

// Run ids labelled on any container or network of the engine.
Result<std::set<std::string>> LabelledRuns(docker::DockerApi& api) {
  docker::LabelSelector any;
  any.equals[std::string(docker::kLabelRun)] = "";  // "" = the label, any value
  std::set<std::string> runs;
  auto containers = api.ListContainers(any, /*all=*/true);
  if (!containers) return containers.error().Context("listing labelled containers");
  for (const docker::ContainerSummary& c : *containers) {
    if (auto it = c.labels.find(std::string(docker::kLabelRun)); it != c.labels.end()) runs.insert(it->second);
  }
  auto networks = api.ListNetworks(any);
  if (!networks) return networks.error().Context("listing labelled networks");
  for (const docker::NetworkInfo& n : *networks) {
    if (auto it = n.labels.find(std::string(docker::kLabelRun)); it != n.labels.end()) runs.insert(it->second);
  }
  return runs;
}

}  // namespace

GcPlan PlanGc(const std::set<std::string>& labelled_runs, const std::string& only_run,
              const std::function<bool(const std::string&)>& is_live) {
  GcPlan plan;
  if (!only_run.empty()) {
    plan.remove.push_back(only_run);
    return plan;
  }
  for (const std::string& run : labelled_runs) {
    if (run.empty()) continue;  // a bare label selects nothing by run: gc --run "" is not a thing
    (is_live(run) ? plan.skip_live : plan.remove).push_back(run);
  }
  return plan;
}

int GcCommand(const GcArgs& args) {
  docker::DockerClientOptions client_options;
  client_options.socket_path = docker::DefaultSocketPath();
  auto client = docker::DockerClient::Connect(client_options);
  if (!client) {
    std::cerr << "swarmbox gc: " << client.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  std::set<std::string> runs;
  if (args.run_id.empty()) {
    auto found = LabelledRuns(**client);
    if (!found) {
      std::cerr << "swarmbox gc: " << found.error().ToString() << "\n";
      return kExitInfrastructure;
    }
    runs = std::move(*found);
  }
  const GcPlan plan = PlanGc(runs, args.run_id, IsRunLive);
  std::size_t containers = 0, networks = 0;
  std::vector<Error> failures;
  for (const std::string& run : plan.remove) {
    docker::LabelSelector selector;
    selector.equals[std::string(docker::kLabelRun)] = run;
    auto report = docker::RemoveLabelled(**client, selector, /*include_images=*/false);
    if (!report) {
      std::cerr << "swarmbox gc: " << report.error().ToString() << "\n";
      return kExitInfrastructure;
    }
    containers += report->containers.size();
    networks += report->networks.size();
    failures.insert(failures.end(), report->failures.begin(), report->failures.end());
  }
  std::cout << "removed " << containers << " containers and " << networks << " networks"
            << (args.run_id.empty() ? "" : " of run " + args.run_id) << "\n";
  for (const std::string& run : plan.skip_live) {
    std::cout << "left run " << run << ": it is still running here (its swarmbox holds "
              << RunLockDir() << "/" << run << ".lock; `swarmbox gc --run " << run
              << "` removes it anyway)\n";
  }
  for (const Error& e : failures) std::cerr << "  failed: " << e.ToString() << "\n";
  return failures.empty() ? kExitOk : kExitInfrastructure;
}

}  // namespace swarmbox::cli
