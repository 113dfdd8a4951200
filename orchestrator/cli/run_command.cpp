// swarmbox run TRIAL.yaml [--out DIR] [--set key=value ...]
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "interrupt.hpp"
#include "load_trial.hpp"
#include "program_images.hpp"
#include "run_lock.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/runner/naming.hpp"
#include "swarmbox/runner/runner.hpp"

namespace swarmbox::cli {

int RunCommand(const RunArgs& args) {
  auto spec = LoadTrialOrPrintError(args.trial, args.sets);
  if (!spec) return kExitUsage;
  docker::DockerClientOptions client_options;
  client_options.socket_path = docker::DefaultSocketPath();
  auto client = docker::DockerClient::Connect(client_options);
  if (!client) {
    std::cerr << "swarmbox run: " << client.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  // Before the (possibly long) image step, so a Ctrl-C there is not lost: the run then ends at once.
  const std::atomic<bool>& interrupted = InstallInterruptHandlers();
  auto images = EnsureTrialImages(**client, args.programs, [&](std::string_view line) {
    if (!args.quiet) std::cerr << "  " << line << "\n";
  });
  if (!images) {
    std::cerr << "swarmbox run: " << images.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  if (interrupted.load()) {  // Ctrl-C during the image step: nothing of the trial exists yet
    std::cerr << "swarmbox run: interrupted (Ctrl-C) before the trial started; nothing was created\n";
    return kExitOutcome;
  }
  // Held until this process ends, however it ends: `swarmbox gc` leaves a live run alone.
  const std::string run_id = args.run_id.empty() ? runner::NewRunId() : args.run_id;
  auto run_lock = RunLock::Acquire(run_id);
  if (!run_lock) {
    std::cerr << "swarmbox run: " << run_lock.error().ToString() << "\n";
    return run_lock.error().code() == ErrorCode::kUnavailable ? kExitUsage : kExitInfrastructure;
  }
  runner::SteadyClock clock;
  runner::RunOptions options;
  options.out_dir = args.out;
  options.run_id = run_id;
  options.images = *images;
  options.interrupted = &interrupted;
  options.progress = args.quiet ? nullptr : &std::cerr;
  auto run = runner::RunTrialSpec(*spec, **client, clock, options);
  if (!run) {
    std::cerr << "swarmbox run: " << run.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  const runner::TrialResult& r = run->result;
  std::cout << run->trial_dir << ": " << dsl::OutcomeName(r.verdict.outcome)
            << (r.verdict.reason.empty() ? "" : " (" + r.verdict.reason + ")") << ", sim "
            << r.sim_s << " s, wall " << r.wall_s << " s\n";
  for (const std::string& p : r.problems) std::cerr << "  note: " << p << "\n";
  if (interrupted.load()) return kExitOutcome;  // the user stopped it: not an infrastructure error
  return runner::ExitCodeFor(r.verdict);
}

}  // namespace swarmbox::cli
