// swarmbox run TRIAL.yaml [-o DIR] [--set key=value ...] [-q] [--json] [--no-record] [--view [ADDR:PORT]]
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "connect_engine.hpp"
#include "interrupt.hpp"
#include "json_out.hpp"
#include "load_trial.hpp"
#include "program_images.hpp"
#include "run_lock.hpp"
#include "swarmbox/docker/engine_endpoint.hpp"
#include "swarmbox/runner/naming.hpp"
#include "swarmbox/runner/runner.hpp"

namespace swarmbox::cli {

namespace {

// The --json summary of a finished trial.
void PrintJsonSummary(const runner::RunOutcome& run, const std::string& run_id, int exit_code) {
  const runner::TrialResult& r = run.result;
  yaml::Node o = yaml::Node::Mapping();
  o.Set("trial_dir", json::Str(run.trial_dir));
  o.Set("run_id", json::Str(run_id));
  o.Set("outcome", json::Str(dsl::OutcomeName(r.verdict.outcome)));
  o.Set("reason", json::Str(r.verdict.reason));
  o.Set("sim_s", json::Num(r.sim_s));
  o.Set("wall_s", json::Num(r.wall_s));
  o.Set("result_json", json::Str((std::filesystem::path(run.trial_dir) / "result.json").string()));
  o.Set("problems", json::Strs(r.problems));
  o.Set("exit_code", json::Int(exit_code));
  json::Print(o);
}

}  // namespace

namespace {

constexpr int kContinue = -1;  // a step's "no exit yet"

// --view: its address, and a local engine (Docker publishes the port on the engine's host: that
// is this machine only with a local engine).
int ResolveView(const RunArgs& args, std::optional<runner::ViewBinding>* view) {
  if (!args.view_requested) return kContinue;
  auto binding = runner::ParseViewAddress(args.view);
  if (!binding) {
    std::cerr << "swarmbox run: --view " << binding.error().message() << "\n";
    return kExitUsage;
  }
  auto endpoint = docker::EngineEndpointFromEnvironment();
  if (endpoint && endpoint->kind != docker::EngineEndpoint::Kind::kUnix && endpoint->host != "127.0.0.1" &&
      endpoint->host != "localhost" && endpoint->host != "::1") {
    std::cerr << "swarmbox run: --view publishes the physics server's port on the Docker engine's host, and the engine ("
              << endpoint->ToString() << ") is not this machine's: --view needs the local engine\n";
    return kExitUsage;
  }
  *view = *binding;
  return kContinue;
}

// The radio profile (the default one is not checked by the loader), before anything starts; the
// warning of a radio model at an rtf it cannot keep.
int CheckRadio(const dsl::TrialSpec& spec) {
  const std::string trials_dir = std::filesystem::absolute(spec.trials_dir).lexically_normal().string();
  if (Status s = runner::CheckRadioProfile(spec, trials_dir); !s) {
    std::cerr << "swarmbox run: " << s.error().ToString() << "\n";
    return kExitUsage;
  }
  if (auto warning = runner::RadioRtfWarning(dsl::RadioModelName(spec.radio.model), spec.rtf)) {
    std::cerr << "swarmbox run: warning: " << *warning << "\n";  // events.jsonl has it too
  }
  return kContinue;
}

// The images of the installed programs; an exit code when they cannot be had or a signal came.
int PrepareImages(const RunArgs& args, docker::DockerClient& client, const std::atomic<bool>& interrupted,
                  runner::Images* out) {
  auto images = EnsureTrialImages(client, args.programs, [&](std::string_view line) {
    if (!args.quiet) std::cerr << "  " << line << "\n";
  });
  if (!images) {
    std::cerr << "swarmbox run: " << images.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  if (interrupted.load()) {  // a signal during the image step: nothing of the trial exists yet
    std::cerr << "swarmbox run: " << InterruptName()
              << " before the trial started; nothing was created\n";
    return InterruptExitCode();
  }
  *out = std::move(*images);
  return kContinue;
}

runner::RunOptions TrialRunOptions(const RunArgs& args, const std::string& run_id, const runner::Images& images,
                                   const std::atomic<bool>& interrupted,
                                   const std::optional<runner::ViewBinding>& view) {
  runner::RunOptions options;
  options.out_dir = args.out;
  options.run_id = run_id;
  options.images = images;
  // A library brain's agent image is packed from the same swarmbox-agent (user_images.hpp).
  if (auto agent_bin = FindProgram("swarmbox-agent", args.programs.agent_bin)) options.agent_binary = *agent_bin;
  options.interrupted = &interrupted;
  options.interrupt_reason = [] { return std::string(InterruptName()); };
  options.progress = args.quiet ? nullptr : &std::cerr;
  options.view = view;
  return options;
}

void PrintRunSummary(const RunArgs& args, const runner::RunOutcome& run, const std::string& run_id, int code) {
  const runner::TrialResult& r = run.result;
  for (const std::string& p : r.problems) std::cerr << "  note: " << p << "\n";
  if (args.json) {
    PrintJsonSummary(run, run_id, code);
  } else {
    std::cout << run.trial_dir << ": " << dsl::OutcomeName(r.verdict.outcome)
              << (r.verdict.reason.empty() ? "" : " (" + r.verdict.reason + ")") << ", sim "
              << r.sim_s << " s, wall " << r.wall_s << " s\n";
  }
}

}  // namespace

int RunCommand(const RunArgs& args) {
  auto spec = LoadTrialOrPrintError(args.trial, args.sets);
  if (!spec) return kExitUsage;
  if (args.no_record) spec->record.enabled = false;
  std::optional<runner::ViewBinding> view;
  if (int code = ResolveView(args, &view); code != kContinue) return code;
  if (int code = CheckRadio(*spec); code != kContinue) return code;
  EngineConnection engine = ConnectEngineOrPrintError("run");
  if (!engine.client) return engine.exit_code;
  docker::DockerClient& client = *engine.client;
  // Before the (possibly long) image step, so a Ctrl-C there is not lost: the run then ends at once.
  const std::atomic<bool>& interrupted = InstallInterruptHandlers();
  runner::Images images;
  if (int code = PrepareImages(args, client, interrupted, &images); code != kContinue) return code;
  // Held until this process ends, however it ends: `swarmbox gc` leaves a live run alone.
  const std::string run_id = args.run_id.empty() ? runner::NewRunId() : args.run_id;
  auto run_lock = RunLock::Acquire(run_id);
  if (!run_lock) {
    std::cerr << "swarmbox run: " << run_lock.error().ToString() << "\n";
    return run_lock.error().code() == ErrorCode::kUnavailable ? kExitUsage : kExitInfrastructure;
  }
  runner::SteadyClock clock;
  const runner::RunOptions options = TrialRunOptions(args, run_id, images, interrupted, view);
  if (view) std::cout << "view: " << view->url() << std::endl;
  auto run = runner::RunTrialSpec(*spec, client, clock, options);
  if (!run) {
    std::cerr << "swarmbox run: " << run.error().ToString() << "\n";
    return interrupted.load() ? InterruptExitCode() : kExitInfrastructure;
  }
  // The user stopped it (130 / 143): neither an infrastructure error nor the trial's own outcome.
  const int code = interrupted.load() ? InterruptExitCode() : runner::ExitCodeFor(run->result.verdict);
  PrintRunSummary(args, *run, run_id, code);
  return code;
}

}  // namespace swarmbox::cli
