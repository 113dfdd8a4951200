// swarmbox gc [--run ID] [--dry-run] [--json]: remove what killed runs left behind, by label.
// --dry-run lists the containers and networks it would remove and removes nothing.
//
// Without --run: every run id labelled on the engine's containers and networks, except the runs
// still alive on this machine (run_lock.hpp: their swarmbox holds the run's lock), which are
// named and left alone: gc must never pull a running trial's network from under it. With
// --run ID: that run, alive or not (the user said which).
#include <iostream>
#include <set>

#include "commands.hpp"
#include "connect_engine.hpp"
#include "json_out.hpp"
#include "run_lock.hpp"
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

namespace {

// What a run has on the engine now, by name.
struct RunLeftovers {
  std::string run;
  std::vector<std::string> containers;
  std::vector<std::string> networks;
};

Result<RunLeftovers> ListRun(docker::DockerApi& api, const std::string& run) {
  docker::LabelSelector selector;
  selector.equals[std::string(docker::kLabelRun)] = run;
  RunLeftovers left{run, {}, {}};
  auto containers = api.ListContainers(selector, /*all=*/true);
  if (!containers) return containers.error().Context("listing the containers of run " + run);
  for (const docker::ContainerSummary& c : *containers) {
    left.containers.push_back(c.names.empty() ? c.id : c.names.front());
  }
  auto networks = api.ListNetworks(selector);
  if (!networks) return networks.error().Context("listing the networks of run " + run);
  for (const docker::NetworkInfo& n : *networks) left.networks.push_back(n.name);
  return left;
}

}  // namespace

namespace {

// What gc did (or would do, with --dry-run): the runs listed, the counts, what failed.
struct GcOutcome {
  std::size_t containers = 0;
  std::size_t networks = 0;
  std::vector<Error> failures;
  std::vector<RunLeftovers> listed;
};

// Lists each run of the plan and removes it (not with --dry-run); an exit code when the engine
// fails.
int RemoveRuns(docker::DockerClient& client, const GcPlan& plan, bool dry_run, GcOutcome* out) {
  for (const std::string& run : plan.remove) {
    auto left = ListRun(client, run);
    if (!left) {
      std::cerr << "swarmbox gc: " << left.error().ToString() << "\n";
      return kExitInfrastructure;
    }
    out->listed.push_back(*left);
    if (dry_run) {
      out->containers += left->containers.size();
      out->networks += left->networks.size();
      continue;
    }
    docker::LabelSelector selector;
    selector.equals[std::string(docker::kLabelRun)] = run;
    auto report = docker::RemoveLabelled(client, selector, /*include_images=*/false);
    if (!report) {
      std::cerr << "swarmbox gc: " << report.error().ToString() << "\n";
      return kExitInfrastructure;
    }
    out->containers += report->containers.size();
    out->networks += report->networks.size();
    out->failures.insert(out->failures.end(), report->failures.begin(), report->failures.end());
  }
  return kExitOk;
}

void PrintGcJson(const GcArgs& args, const GcPlan& plan, const GcOutcome& g, int code) {
  yaml::Node o = yaml::Node::Mapping();
  o.Set("dry_run", json::Bool(args.dry_run));
  yaml::Node list = yaml::Node::Sequence();
  for (const RunLeftovers& r : g.listed) {
    yaml::Node item = yaml::Node::Mapping();
    item.Set("run", json::Str(r.run));
    item.Set("containers", json::Strs(r.containers));
    item.Set("networks", json::Strs(r.networks));
    list.Append(std::move(item));
  }
  o.Set("runs", std::move(list));
  o.Set(args.dry_run ? "would_remove_containers" : "removed_containers",
        json::Int(static_cast<std::int64_t>(g.containers)));
  o.Set(args.dry_run ? "would_remove_networks" : "removed_networks",
        json::Int(static_cast<std::int64_t>(g.networks)));
  o.Set("left_live", json::Strs(plan.skip_live));
  std::vector<std::string> failed;
  for (const Error& e : g.failures) failed.push_back(e.ToString());
  o.Set("failures", json::Strs(failed));
  o.Set("exit_code", json::Int(code));
  json::Print(o);
}

void PrintGcText(const GcArgs& args, const GcPlan& plan, const GcOutcome& g) {
  const std::string of_run = args.run_id.empty() ? "" : " of run " + args.run_id;
  if (args.dry_run) {
    std::cout << "would remove " << g.containers << " containers and " << g.networks << " networks"
              << of_run << " (dry run: nothing removed)\n";
    for (const RunLeftovers& r : g.listed) {
      for (const std::string& c : r.containers) std::cout << "  container " << c << "  run " << r.run << "\n";
      for (const std::string& n : r.networks) std::cout << "  network " << n << "  run " << r.run << "\n";
    }
  } else {
    std::cout << "removed " << g.containers << " containers and " << g.networks << " networks" << of_run
              << "\n";
  }
  for (const std::string& run : plan.skip_live) {
    std::cout << "left run " << run << ": it is still running here (its swarmbox holds "
              << RunLockDir() << "/" << run << ".lock; `swarmbox gc --run " << run
              << "` removes it anyway)\n";
  }
}

}  // namespace

int GcCommand(const GcArgs& args) {
  EngineConnection engine = ConnectEngineOrPrintError("gc");
  if (!engine.client) return engine.exit_code;
  docker::DockerClient& client = *engine.client;
  std::set<std::string> runs;
  if (args.run_id.empty()) {
    auto found = LabelledRuns(client);
    if (!found) {
      std::cerr << "swarmbox gc: " << found.error().ToString() << "\n";
      return kExitInfrastructure;
    }
    runs = std::move(*found);
  }
  const GcPlan plan = PlanGc(runs, args.run_id, IsRunLive);
  GcOutcome outcome;
  if (int code = RemoveRuns(client, plan, args.dry_run, &outcome); code != kExitOk) return code;
  for (const Error& e : outcome.failures) std::cerr << "  failed: " << e.ToString() << "\n";
  const int code = outcome.failures.empty() ? kExitOk : kExitInfrastructure;
  if (args.json) {
    PrintGcJson(args, plan, outcome, code);
  } else {
    PrintGcText(args, plan, outcome);
  }
  return code;
}

}  // namespace swarmbox::cli
