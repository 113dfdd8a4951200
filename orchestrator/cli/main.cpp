// swarmbox: the command-line program (ARCHITECTURE.md "CLI", contract). Thin: parsing only; each
// subcommand lives in its own file.
#include <CLI/CLI.hpp>

#include "commands.hpp"

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
  run_cmd->add_option("--set", run.sets, "Override a key of the trial: key.path=value")
      ->allow_extra_args(false);
  run_cmd->add_option("--run-id", run.run_id, "Run id (default: UTC time + random)");
  run_cmd->add_flag("--quiet", run.quiet, "No progress on the terminal");
  run_cmd->add_option("--physics-bin", run.programs.physics_bin, "Host-built swarmbox-physics");
  run_cmd->add_option("--agent-bin", run.programs.agent_bin, "Host-built swarmbox-agent");

  ValidateArgs validate;
  auto* validate_cmd = app.add_subcommand("validate", "Check trial files (file:line:col: message)");
  validate_cmd->add_option("files", validate.files, "Trial descriptions")->required();
  validate_cmd->add_option("--set", validate.sets, "Override a key: key.path=value")
      ->allow_extra_args(false);

  ComposeArgs compose;
  auto* compose_cmd = app.add_subcommand("compose", "Export a trial as a docker-compose file");
  compose_cmd->add_option("trial", compose.trial, "Trial description (YAML)")->required();
  compose_cmd->add_option("-o,--output", compose.output, "Write here (default: stdout)");
  compose_cmd->add_option("--set", compose.sets, "Override a key: key.path=value")
      ->allow_extra_args(false);
  compose_cmd->add_option("--physics-image", compose.physics_image, "Image tag (default: packed)");
  compose_cmd->add_option("--agent-image", compose.agent_image, "Image tag (default: packed)");
  compose_cmd->add_option("--physics-bin", compose.programs.physics_bin, "Host-built swarmbox-physics");
  compose_cmd->add_option("--agent-bin", compose.programs.agent_bin, "Host-built swarmbox-agent");

  ImagesArgs images;
  bool no_faults = false;
  auto* images_cmd = app.add_subcommand("images", "Build the registry-free images (only what is missing)");
  images_cmd->add_option("--physics-bin", images.programs.physics_bin, "Host-built swarmbox-physics");
  images_cmd->add_option("--agent-bin", images.programs.agent_bin, "Host-built swarmbox-agent");
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
  exp_cmd->add_option("--set", exp.sets,
                      "Override a key of every trial: key.path=value (after the file's set:, "
                      "before the factor levels)")
      ->allow_extra_args(false);
  exp_cmd->add_option("--max-attempts", exp.max_attempts,
                      "Attempts per trial when hosts fail under it (default 3)")
      ->check(CLI::Range(1, 20));
  exp_cmd->add_option("--run-id", exp.run_id, "Run id (default: UTC time + random)");
  exp_cmd->add_flag("--quiet", exp.quiet, "No progress on the terminal");
  exp_cmd->add_option("--physics-bin", exp.programs.physics_bin, "Host-built swarmbox-physics");
  exp_cmd->add_option("--agent-bin", exp.programs.agent_bin, "Host-built swarmbox-agent");

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
