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

#include <atomic>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "interrupt.hpp"
#include "json_out.hpp"
#include "program_images.hpp"
#include "run_lock.hpp"
#include "swarmbox/experiment/experiment_runner.hpp"
#include "swarmbox/experiment/experiment_spec.hpp"
#include "swarmbox/experiment/host_pool.hpp"
#include "swarmbox/experiment/trial_store.hpp"
#include "swarmbox/hosts/host_spec.hpp"
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

// The experiment with the command line's filter and --set overrides, every trial loaded and
// checked; nullopt (the error printed) on bad input.
std::optional<experiment::ExperimentPlan> PlanFromArgs(const ExperimentArgs& args) {
  auto spec = experiment::LoadExperiment(args.experiment);
  if (!spec) {
    std::cerr << spec.error().ToString() << "\n";
    return std::nullopt;
  }
  if (!args.filter.empty()) spec->filter = args.filter;
  spec->set.insert(spec->set.end(), args.sets.begin(), args.sets.end());
  auto plan = experiment::PlanExperiment(*spec);
  if (!plan) {
    std::cerr << plan.error().ToString() << "\n";
    return std::nullopt;
  }
  return std::move(*plan);
}

// --hosts, else the file's hosts:, else the local engine; nullopt (the error printed) on bad input.
std::optional<std::vector<hosts::HostSpec>> HostSpecsFromArgs(const ExperimentArgs& args,
                                                             const experiment::ExperimentSpec& spec) {
  const std::vector<std::string> host_texts =
      !args.hosts.empty() ? args.hosts : (!spec.hosts.empty() ? spec.hosts : std::vector<std::string>{"local"});
  auto host_specs = hosts::ParseHostSpecs(host_texts);
  if (!host_specs) {
    std::cerr << host_specs.error().ToString() << "\n";
    return std::nullopt;
  }
  return std::move(*host_specs);
}

// --resume of a run whose every trial has a result: the reports again, nothing run.
int ReportDone(const ExperimentArgs& args, const experiment::ExperimentPlan& plan, const std::string& run_id,
               const std::string& out) {
  std::vector<std::string> problems;
  (void)experiment::WriteReports(out, &problems);
  if (args.json) {
    PrintJsonSummary(plan.spec.name, run_id, out, plan.trials.size(), plan.trials.size(), {}, problems, kExitOk);
    return kExitOk;
  }
  std::cout << out << ": " << plan.trials.size() << "/" << plan.trials.size() << " trials already have a result; "
            << out << "/results.csv, " << out << "/report.html\n";
  return kExitOk;
}

// Each host connected (ssh tunnels for ssh:// hosts) and given the images built from the programs
// found for this swarmbox; build progress on stderr unless -q.
experiment::HostPoolSetup PoolSetup(const ExperimentArgs& args, const std::string& workdir) {
  experiment::HostPoolSetup setup;
  setup.connect = experiment::ConnectThroughHosts(workdir);
  setup.trial_images = [&args](docker::DockerApi& api, const experiment::ImageProgressFn& progress) {
    return EnsureTrialImages(api, args.programs, progress);
  };
  setup.on_left_out = [](const std::string& host, const std::string& why) {
    std::cerr << "swarmbox experiment: host " << host << " left out: " << why << "\n";
  };
  if (!args.quiet) {
    setup.on_progress = [](const std::string& host, std::string_view line) {
      std::cerr << "  [" << host << "] " << line << "\n";
    };
  }
  return setup;
}

experiment::ExperimentOptions OptionsFor(const ExperimentArgs& args, const std::string& out,
                                         const std::string& run_id, const std::atomic<bool>& interrupted) {
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
  return options;
}

// The summary on stdout (or as JSON) and the exit code.
int ReportSummary(const ExperimentArgs& args, const std::string& name, const std::string& run_id,
                  const std::string& out, const experiment::ExperimentSummary& summary, bool interrupted) {
  for (const std::string& p : summary.problems) std::cerr << "  note: " << p << "\n";
  int code = kExitOk;
  if (interrupted) {
    code = InterruptExitCode();
  } else if (summary.committed < summary.total) {
    std::cerr << "swarmbox experiment: " << (summary.total - summary.committed)
              << " trials have no result: run again with --resume --out " << out << "\n";
    code = kExitInfrastructure;
  }
  if (args.json) {
    std::map<std::string, int> outcomes;
    for (const auto& [outcome, n] : summary.outcomes) outcomes[outcome] = static_cast<int>(n);
    PrintJsonSummary(name, run_id, out, summary.total, summary.committed, outcomes, summary.problems, code);
    return code;
  }
  std::cout << out << ": " << summary.committed << "/" << summary.total << " trials";
  std::string sep = " (";
  for (const auto& [outcome, n] : summary.outcomes) {
    std::cout << sep << outcome << " " << n;
    sep = ", ";
  }
  std::cout << (summary.outcomes.empty() ? "" : ")") << "; " << out << "/results.csv, " << out << "/report.html\n";
  return code;
}

// The trials over the pool of usable hosts; the forwarded sockets live in a short private folder
// (unix socket paths are limited to 108 bytes), removed at the end.
int RunOnHosts(const ExperimentArgs& args, const experiment::ExperimentPlan& plan,
               const std::vector<hosts::HostSpec>& host_specs, const std::string& run_id, const std::string& out,
               const std::atomic<bool>& interrupted) {
  const std::string workdir = "/tmp/swarmbox-" + run_id;
  std::error_code ec;
  experiment::HostPool pool = experiment::PrepareHostPool(plan, host_specs, PoolSetup(args, workdir));
  if (pool.hosts().empty()) {
    std::cerr << "swarmbox experiment: no host is usable (see above)\n";
    fs::remove_all(workdir, ec);
    return kExitInfrastructure;
  }
  if (interrupted.load()) {
    std::cerr << "swarmbox experiment: " << InterruptName() << " before any trial started\n";
    return InterruptExitCode();
  }
  auto summary = experiment::RunExperiment(plan, pool.hosts(), OptionsFor(args, out, run_id, interrupted));
  pool.Disconnect();  // closes the tunnels
  fs::remove_all(workdir, ec);
  if (!summary) {
    std::cerr << "swarmbox experiment: " << summary.error().ToString() << "\n";
    return summary.error().code() == ErrorCode::kInvalidArgument ? kExitUsage : kExitInfrastructure;
  }
  return ReportSummary(args, plan.spec.name, run_id, out, *summary, interrupted.load());
}

}  // namespace

int ExperimentCommand(const ExperimentArgs& args) {
  auto plan = PlanFromArgs(args);
  if (!plan) return kExitUsage;
  if (args.resume && args.out.empty()) {
    std::cerr << "swarmbox experiment: --resume needs --out DIR (the folder of the run to resume)\n";
    return kExitUsage;
  }
  auto host_specs = HostSpecsFromArgs(args, plan->spec);
  if (!host_specs) return kExitUsage;
  const std::string run_id = args.run_id.empty() ? runner::NewRunId() : args.run_id;
  // Held until this process ends, however it ends: `swarmbox gc` leaves a live experiment alone.
  auto run_lock = RunLock::Acquire(run_id);
  if (!run_lock) {
    std::cerr << "swarmbox experiment: " << run_lock.error().ToString() << "\n";
    return run_lock.error().code() == ErrorCode::kUnavailable ? kExitUsage : kExitInfrastructure;
  }
  const std::string out = args.out.empty() ? "runs/" + plan->spec.name + "-" + run_id : args.out;
  if (auto checked = experiment::CheckOutFolder(*plan, out, args.resume); !checked) {
    std::cerr << "swarmbox experiment: " << checked.error().ToString() << "\n";
    return kExitUsage;
  }
  if (args.resume && experiment::TrialStore(out).Pending(plan->trials).empty()) {
    return ReportDone(args, *plan, run_id, out);
  }
  const std::atomic<bool>& interrupted = InstallInterruptHandlers();
  if (!args.quiet) {
    std::cerr << "swarmbox experiment " << plan->spec.name << ": " << plan->trials.size() << " trials, run "
              << run_id << " -> " << out << "\n";
  }
  return RunOnHosts(args, *plan, *host_specs, run_id, out, interrupted);
}

}  // namespace swarmbox::cli
