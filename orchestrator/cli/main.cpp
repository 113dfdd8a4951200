// swarmbox: the command-line program (ARCHITECTURE.md "CLI", contract). Thin: parsing only; each
// subcommand lives in its own file.
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace {

using swarmbox::cli::ProgramPaths;

// --physics-bin and --agent-bin: where the host-built programs for the images come from.
void AddProgramOptions(CLI::App* cmd, ProgramPaths& programs) {
  cmd->add_option("--physics-bin", programs.physics_bin, "Host-built swarmbox-physics");
  cmd->add_option("--agent-bin", programs.agent_bin, "Host-built swarmbox-agent");
}

// --set key.path=value, repeatable; one value per --set, so a positional argument after it is not
// taken as another override.
void AddSetOption(CLI::App* cmd, std::vector<std::string>& sets, const std::string& help) {
  cmd->add_option("--set", sets, help)->allow_extra_args(false);
}

// What `run` and `experiment` share after their own options: --run-id, --quiet and the programs.
void AddLaunchOptions(CLI::App* cmd, std::string& run_id, bool& quiet, ProgramPaths& programs) {
  cmd->add_option("--run-id", run_id, "Run id (default: UTC time + random)");
  cmd->add_flag("--quiet", quiet, "No progress on the terminal");
  AddProgramOptions(cmd, programs);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace swarmbox::cli;
  CLI::App app{"SwarmBox: a containerised SITL fleet for a search-and-rescue drone swarm.\n"
               "Exit codes: 0 success, 1 another trial outcome, 2 bad input or usage, "
               "3 infrastructure error.",
               "swarmbox"};
  app.require_subcommand(1);

  RunArgs run;
  auto* run_cmd = app.add_subcommand("run", "Run one trial and write <out>/<trial>-<run id>/");
  run_cmd->add_option("trial", run.trial, "Trial description (YAML)")->required();
  run_cmd->add_option("--out", run.out, "Output folder (default: runs)");
  AddSetOption(run_cmd, run.sets, "Override a key of the trial: key.path=value");
  AddLaunchOptions(run_cmd, run.run_id, run.quiet, run.programs);

  ValidateArgs validate;
  auto* validate_cmd = app.add_subcommand("validate", "Check trial files (file:line:col: message)");
  validate_cmd->add_option("files", validate.files, "Trial descriptions")->required();
  AddSetOption(validate_cmd, validate.sets, "Override a key: key.path=value");

  ComposeArgs compose;
  auto* compose_cmd = app.add_subcommand("compose", "Export a trial as a docker-compose file");
  compose_cmd->add_option("trial", compose.trial, "Trial description (YAML)")->required();
  compose_cmd->add_option("-o,--output", compose.output, "Write here (default: stdout)");
  AddSetOption(compose_cmd, compose.sets, "Override a key: key.path=value");
  compose_cmd->add_option("--physics-image", compose.physics_image, "Image tag (default: packed)");
  compose_cmd->add_option("--agent-image", compose.agent_image, "Image tag (default: packed)");
  AddProgramOptions(compose_cmd, compose.programs);

  ImagesArgs images;
  bool no_faults = false;
  auto* images_cmd = app.add_subcommand("images", "Build the registry-free images (only what is missing)");
  AddProgramOptions(images_cmd, images.programs);
  images_cmd->add_flag("--no-faults", no_faults, "Skip the fault-injection sidecar image");

  ExperimentArgs exp;
  auto* exp_cmd = app.add_subcommand(
      "experiment", "Run an experiment's trials over a pool of hosts into <out>/ (resumable)");
  exp_cmd->add_option("experiment", exp.experiment, "Experiment description (YAML)")->required();
  exp_cmd->add_option("--out", exp.out, "Output folder (default: runs/<name>-<run id>)");
  exp_cmd->add_option("--hosts", exp.hosts,
                      "Hosts: local[?slots=N], ssh://user@host[:port][?slots=N&socket=PATH&"
                      "identity=KEY&known_hosts=FILE] (default: the file's hosts, else local)")
      ->allow_extra_args(false);
  exp_cmd->add_flag("--resume", exp.resume, "Run only the trials of --out without result.json");
  exp_cmd->add_option("--filter", exp.filter, "Run only codes matching a pattern (? = any level)")
      ->allow_extra_args(false);
  AddSetOption(exp_cmd, exp.sets,
               "Override a key of every trial: key.path=value (after the file's set:, "
               "before the factor levels)");
  exp_cmd->add_option("--max-attempts", exp.max_attempts,
                      "Attempts per trial when hosts fail under it (default 3)")
      ->check(CLI::Range(1, 20));
  AddLaunchOptions(exp_cmd, exp.run_id, exp.quiet, exp.programs);

  ReportArgs report;
  auto* report_cmd =
      app.add_subcommand("report", "Regenerate results.csv and report.html of an experiment folder");
  report_cmd->add_option("dir", report.dir, "Experiment folder")->required();

  GcArgs gc;
  auto* gc_cmd = app.add_subcommand("gc", "Remove containers and networks left by killed runs");
  gc_cmd->add_option("--run", gc.run_id, "Only this run id (default: every run)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  if (*run_cmd) return RunCommand(run);
  if (*validate_cmd) return ValidateCommand(validate);
  if (*compose_cmd) return ComposeCommand(compose);
  if (*images_cmd) {
    images.faults = !no_faults;
    return ImagesCommand(images);
  }
  if (*exp_cmd) return ExperimentCommand(exp);
  if (*report_cmd) return ReportCommand(report);
  if (*gc_cmd) return GcCommand(gc);
  return kExitUsage;
}
