// swarmbox experiment EXPERIMENT.yaml [-o DIR] [--hosts SPEC ...] [--resume] [--filter P]
//                                    [--set key=value ...] [-q] [--json]
//
// Loads and checks the experiment and every trial it expands to (exit 2 on bad input), connects
// the hosts (ssh tunnels for ssh:// hosts), builds the images on each host that lacks them, then
// runs the trials over every slot (experiment_runner.hpp) with a live board on stderr. Exit 0 when
// every trial of the experiment has an outcome (result.json), 3 when some could not be run (no host
// left, image builds failed: --resume runs them later), 130 / 143 when stopped with Ctrl-C /
// SIGTERM (after the clean-up), 2 bad input. --json: the summary as one JSON object on stdout.
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "commands.hpp"
#include "interrupt.hpp"
#include "json_out.hpp"
#include "program_images.hpp"
#include "run_lock.hpp"
#include "swarmbox/experiment/experiment_runner.hpp"
#include "swarmbox/experiment/experiment_spec.hpp"
#include "swarmbox/experiment/trial_store.hpp"
#include "swarmbox/hosts/host.hpp"
#include "swarmbox/runner/naming.hpp"

namespace swarmbox::cli {

namespace fs = std::filesystem;

namespace {

// The --json summary.
void PrintJsonSummary(const std::string& name, const std::string& run_id, const std::string& out,
                      std::size_t total, std::size_t committed,
                      const std::map<std::string, int>& outcomes,
                      const std::vector<std::string>& problems, int exit_code) {
  yaml::Node o = yaml::Node::Mapping();
  o.Set("experiment", json::Str(name));
  o.Set("run_id", json::Str(run_id));
  o.Set("out", json::Str(out));
  o.Set("total", json::Int(static_cast<std::int64_t>(total)));
  o.Set("committed", json::Int(static_cast<std::int64_t>(committed)));
  yaml::Node by_outcome = yaml::Node::Mapping();
  for (const auto& [outcome, n] : outcomes) by_outcome.Set(outcome, json::Int(n));
  o.Set("outcomes", std::move(by_outcome));
  o.Set("results_csv", json::Str(out + "/results.csv"));
  o.Set("report_html", json::Str(out + "/report.html"));
  o.Set("problems", json::Strs(problems));
  o.Set("exit_code", json::Int(exit_code));
  json::Print(o);
}

}  // namespace

int ExperimentCommand(const ExperimentArgs& args) {
  auto spec = experiment::LoadExperiment(args.experiment);
  if (!spec) {
    std::cerr << spec.error().ToString() << "\n";
    return kExitUsage;
  }
  if (!args.filter.empty()) spec->filter = args.filter;
  spec->set.insert(spec->set.end(), args.sets.begin(), args.sets.end());
  auto plan = experiment::PlanExperiment(*spec);
  if (!plan) {
    std::cerr << plan.error().ToString() << "\n";
    return kExitUsage;
  }
  if (args.resume && args.out.empty()) {
    std::cerr << "swarmbox experiment: --resume needs --out DIR (the folder of the run to resume)\n";
    return kExitUsage;
  }
  const std::vector<std::string> host_texts =
      !args.hosts.empty() ? args.hosts
                          : (!spec->hosts.empty() ? spec->hosts : std::vector<std::string>{"local"});
  auto host_specs = hosts::ParseHostSpecs(host_texts);
  if (!host_specs) {
    std::cerr << host_specs.error().ToString() << "\n";
    return kExitUsage;
  }
  const std::string run_id = args.run_id.empty() ? runner::NewRunId() : args.run_id;
  // Held until this process ends, however it ends: `swarmbox gc` leaves a live experiment alone.
  auto run_lock = RunLock::Acquire(run_id);
  if (!run_lock) {
    std::cerr << "swarmbox experiment: " << run_lock.error().ToString() << "\n";
    return run_lock.error().code() == ErrorCode::kUnavailable ? kExitUsage : kExitInfrastructure;
  }
  const std::string out = args.out.empty() ? "runs/" + spec->name + "-" + run_id : args.out;
  if (auto checked = experiment::CheckOutFolder(*plan, out, args.resume); !checked) {
    std::cerr << "swarmbox experiment: " << checked.error().ToString() << "\n";
    return kExitUsage;
  }
  if (args.resume && experiment::TrialStore(out).Pending(plan->trials).empty()) {
    std::vector<std::string> problems;
    (void)experiment::WriteReports(out, &problems);
    if (args.json) {
      PrintJsonSummary(spec->name, run_id, out, plan->trials.size(), plan->trials.size(), {},
                       problems, kExitOk);
      return kExitOk;
    }
    std::cout << out << ": " << plan->trials.size() << "/" << plan->trials.size()
              << " trials already have a result; " << out << "/results.csv, " << out
              << "/report.html\n";
    return kExitOk;
  }
  const std::atomic<bool>& interrupted = InstallInterruptHandlers();
  auto say = [&](const std::string& line) {
    if (!args.quiet) std::cerr << line << "\n";
  };
  say("swarmbox experiment " + spec->name + ": " + std::to_string(plan->trials.size()) +
      " trials, run " + run_id + " -> " + out);

  // Hosts: connect and build the images, each host on its own thread (a remote build is slow).
  // Forwarded sockets live in a short private folder (unix socket paths are limited to 108 bytes).
  const std::string workdir = "/tmp/swarmbox-" + run_id;
  std::vector<std::unique_ptr<hosts::Host>> connected(host_specs->size());
  std::vector<runner::Images> images(host_specs->size());
  std::vector<std::string> faults_images(host_specs->size());
  std::mutex say_mu;
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < host_specs->size(); ++i) {
    threads.emplace_back([&, i] {
      const hosts::HostSpec& hs = (*host_specs)[i];
      auto host = hosts::ConnectHost(hs, workdir);
      if (!host) {
        std::lock_guard lock(say_mu);
        std::cerr << "swarmbox experiment: host " << hs.name() << " left out: "
                  << host.error().ToString() << "\n";
        return;
      }
      auto built = EnsureTrialImages((*host)->api(), args.programs, [&](std::string_view line) {
        if (args.quiet) return;
        std::lock_guard lock(say_mu);
        std::cerr << "  [" << hs.name() << "] " << line << "\n";
      });
      if (!built) {
        std::lock_guard lock(say_mu);
        std::cerr << "swarmbox experiment: host " << hs.name()
                  << " left out: images: " << built.error().ToString() << "\n";
        return;
      }
      auto faults = experiment::EnsurePlanFaultsImage(*plan, (*host)->api(), [&](std::string_view line) {
        if (args.quiet) return;
        std::lock_guard lock(say_mu);
        std::cerr << "  [" << hs.name() << "] " << line << "\n";
      });
      if (!faults) {
        std::lock_guard lock(say_mu);
        std::cerr << "swarmbox experiment: host " << hs.name()
                  << " left out: images: " << faults.error().ToString() << "\n";
        return;
      }
      images[i] = *built;
      faults_images[i] = *faults;
      connected[i] = std::move(*host);
    });
  }
  for (std::thread& t : threads) t.join();
  std::vector<experiment::PoolHost> pool;
  for (std::size_t i = 0; i < connected.size(); ++i) {
    if (!connected[i]) continue;
    hosts::Host* h = connected[i].get();
    pool.push_back({h->name(), h->slots(), &h->api(), [h] { return h->Check(); }, images[i],
                    faults_images[i]});
  }
  if (pool.empty()) {
    std::cerr << "swarmbox experiment: no host is usable (see above)\n";
    std::error_code ec;
    fs::remove_all(workdir, ec);
    return kExitInfrastructure;
  }
  if (interrupted.load()) {
    std::cerr << "swarmbox experiment: " << InterruptName() << " before any trial started\n";
    return InterruptExitCode();
  }

  experiment::ExperimentOptions options;
  options.out_dir = out;
  options.run_id = run_id;
  options.resume = args.resume;
  // Library brains: their agent images are packed from this swarmbox-agent on each host.
  if (auto agent_bin = FindProgram("swarmbox-agent", args.programs.agent_bin)) {
    options.trial_options.agent_binary = *agent_bin;
  }
  options.max_attempts = args.max_attempts;
  options.interrupted = &interrupted;
  options.progress = args.quiet ? nullptr : &std::cerr;
  options.progress_tty = !args.quiet && ::isatty(STDERR_FILENO) == 1;
  auto summary = experiment::RunExperiment(*plan, pool, options);
  connected.clear();  // closes the tunnels
  std::error_code ec;
  fs::remove_all(workdir, ec);
  if (!summary) {
    std::cerr << "swarmbox experiment: " << summary.error().ToString() << "\n";
    return summary.error().code() == ErrorCode::kInvalidArgument ? kExitUsage : kExitInfrastructure;
  }
  for (const std::string& p : summary->problems) std::cerr << "  note: " << p << "\n";
  int code = kExitOk;
  if (interrupted.load()) {
    code = InterruptExitCode();
  } else if (summary->committed < summary->total) {
    std::cerr << "swarmbox experiment: " << (summary->total - summary->committed)
              << " trials have no result: run again with --resume --out " << out << "\n";
    code = kExitInfrastructure;
  }
  if (args.json) {
    std::map<std::string, int> outcomes;
    for (const auto& [outcome, n] : summary->outcomes) outcomes[outcome] = static_cast<int>(n);
    PrintJsonSummary(spec->name, run_id, out, summary->total, summary->committed, outcomes,
                     summary->problems, code);
    return code;
  }
  std::cout << out << ": " << summary->committed << "/" << summary->total << " trials";
  std::string sep = " (";
  for (const auto& [outcome, n] : summary->outcomes) {
    std::cout << sep << outcome << " " << n;
    sep = ", ";
  }
  std::cout << (summary->outcomes.empty() ? "" : ")") << "; " << out << "/results.csv, " << out
            << "/report.html\n";
  return code;
}

}  // namespace swarmbox::cli
