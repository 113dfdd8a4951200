// swarmbox: the command-line program (ARCHITECTURE.md "CLI", contract). Thin: parsing only; each
// subcommand lives in its own file.
#include <CLI/CLI.hpp>

#include <iostream>

#include "commands.hpp"
#include "json_out.hpp"
#include "swarmbox/common/version.hpp"

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

// -o,--out: the one spelling of "where the output goes" on every subcommand.
void AddOutOption(CLI::App* cmd, std::string& out, const std::string& help) {
  cmd->add_option("-o,--out", out, help);
}

// -q,--quiet: no progress on stderr (results and errors still print).
void AddQuietFlag(CLI::App* cmd, bool& quiet) {
  cmd->add_flag("-q,--quiet", quiet, "No progress on the terminal (errors still print)");
}

// --json: the summary as one JSON object on stdout; progress stays on stderr.
void AddJsonFlag(CLI::App* cmd, bool& json) {
  cmd->add_flag("--json", json, "Print the summary as one JSON object on stdout (progress on stderr)");
}

// What `run` and `experiment` share after their own options: --run-id, --quiet, --json and the
// programs.
void AddLaunchOptions(CLI::App* cmd, std::string& run_id, bool& quiet, bool& json,
                      ProgramPaths& programs) {
  cmd->add_option("--run-id", run_id, "Run id (default: UTC time + random)");
  AddQuietFlag(cmd, quiet);
  AddJsonFlag(cmd, json);
  AddProgramOptions(cmd, programs);
}

constexpr char kExitCodes[] =
    "Exit codes: 0 success, 1 another trial outcome, 2 bad input or usage, 3 infrastructure error "
    "(no Docker engine, image build failed), 130 run/experiment interrupted by Ctrl-C (SIGINT), "
    "143 run/experiment stopped by SIGTERM (both after the clean-up: nothing labelled with the run "
    "is left).\n"
    "Engine: $DOCKER_HOST (unix://PATH, tcp://HOST:PORT with $DOCKER_TLS_VERIFY and "
    "$DOCKER_CERT_PATH as the docker CLI reads them; default unix:///var/run/docker.sock).";

constexpr char kDiffHelp[] =
    "Compared: truth.csv row by row (the first row that differs: simulated time, drone, each "
    "differing column with both values, or which file ended first); events.jsonl per stream (a "
    "container's log events; the orchestrator's records by target, fault, mesh node), the earliest "
    "divergence by simulated time; result.json's outcome and reason.\n"
    "Not compared (wall-clock by nature): events.jsonl fields with 'wall' as a word of their name "
    "(wall_s, requested_wall_s, ...), rtf, late of event=clock, detected and host of the mechanism "
    "record; the run id inside values (container names, paths). A trial that ended on a log line "
    "is compared up to that line's simulated time.\n"
    "Exit codes: 0 identical, 1 they differ, 2 not a trial folder, or a file that cannot be read "
    "or parsed.";

using namespace swarmbox::cli;

// Every subcommand's arguments and its parsed-or-not flag, filled by CLI11.
struct Subcommands {
  RunArgs run;
  ValidateArgs validate;
  ComposeArgs compose;
  ImagesArgs images;
  bool no_faults = false;
  ExperimentArgs exp;
  ReportArgs report;
  DiffArgs diff;
  ViewArgs view;
  GcArgs gc;
  bool version_json = false;
  CLI::App* run_cmd = nullptr;
  CLI::App* validate_cmd = nullptr;
  CLI::App* compose_cmd = nullptr;
  CLI::App* images_cmd = nullptr;
  CLI::App* exp_cmd = nullptr;
  CLI::App* report_cmd = nullptr;
  CLI::App* diff_cmd = nullptr;
  CLI::App* view_cmd = nullptr;
  CLI::App* gc_cmd = nullptr;
  CLI::App* version_cmd = nullptr;
};

void AddRunCommand(CLI::App& app, Subcommands& s) {
  RunArgs& run = s.run;
  auto* run_cmd = s.run_cmd = app.add_subcommand("run", "Run one trial and write <out>/<trial>-<run id>/");
  run_cmd->add_option("trial", run.trial, "Trial description (YAML)")->required();
  AddOutOption(run_cmd, run.out, "Output folder (default: runs)");
  AddSetOption(run_cmd, run.sets, "Override a key of the trial: key.path=value");
  AddLaunchOptions(run_cmd, run.run_id, run.quiet, run.json, run.programs);
  run_cmd->add_flag("--no-record", run.no_record, "No recording.mcap (as the trial key record: {enabled: false})");
  run_cmd->add_option("--view", run.view, "Serve the trial live (Foxglove WebSocket and the built-in page) on this host at ADDR:PORT (default 127.0.0.1:8765); the local Docker engine only")
      ->expected(0, 1);
}

void AddValidateCommand(CLI::App& app, Subcommands& s) {
  ValidateArgs& validate = s.validate;
  auto* validate_cmd = s.validate_cmd = app.add_subcommand(
      "validate", "Check trial and experiment files (file:line:col: message); an experiment with "
                  "every trial it expands to");
  validate_cmd->add_option("files", validate.files, "Trial or experiment descriptions")->required();
  AddSetOption(validate_cmd, validate.sets, "Override a key (of every trial): key.path=value");
  AddJsonFlag(validate_cmd, validate.json);
}

void AddComposeCommand(CLI::App& app, Subcommands& s) {
  ComposeArgs& compose = s.compose;
  auto* compose_cmd = s.compose_cmd = app.add_subcommand("compose", "Export a trial as a docker-compose file");
  compose_cmd->add_option("trial", compose.trial, "Trial description (YAML)")->required();
  AddOutOption(compose_cmd, compose.output, "Write here (default: stdout)");
  compose_cmd->add_option("--output", compose.output, "Old spelling of --out")->group("");
  AddSetOption(compose_cmd, compose.sets, "Override a key: key.path=value");
  compose_cmd->add_option("--physics-image", compose.physics_image, "Image tag (default: packed)");
  compose_cmd->add_option("--agent-image", compose.agent_image, "Image tag (default: packed)");
  AddProgramOptions(compose_cmd, compose.programs);
}

void AddImagesCommand(CLI::App& app, Subcommands& s) {
  ImagesArgs& images = s.images;
  auto* images_cmd = s.images_cmd = app.add_subcommand("images", "Build the registry-free images (only what is missing)");
  AddProgramOptions(images_cmd, images.programs);
  images_cmd->add_flag("--no-faults", s.no_faults, "Skip the fault-injection sidecar image");
  AddQuietFlag(images_cmd, images.quiet);
  AddJsonFlag(images_cmd, images.json);
}

void AddExperimentCommand(CLI::App& app, Subcommands& s) {
  ExperimentArgs& exp = s.exp;
  auto* exp_cmd = s.exp_cmd = app.add_subcommand(
      "experiment", "Run an experiment's trials over a pool of hosts into <out>/ (resumable)");
  exp_cmd->add_option("experiment", exp.experiment, "Experiment description (YAML)")->required();
  AddOutOption(exp_cmd, exp.out, "Output folder (default: runs/<name>-<run id>)");
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
  AddLaunchOptions(exp_cmd, exp.run_id, exp.quiet, exp.json, exp.programs);
}

// report, diff, view: the commands that read a run's folders.
void AddFolderCommands(CLI::App& app, Subcommands& s) {
  ReportArgs& report = s.report;
  auto* report_cmd = s.report_cmd =
      app.add_subcommand("report", "Regenerate results.csv and report.html of an experiment folder");
  report_cmd->add_option("dir", report.dir, "Experiment folder")->required();

  DiffArgs& diff = s.diff;
  auto* diff_cmd = s.diff_cmd = app.add_subcommand(
      "diff", "The first divergence between two trial folders; exit 0 identical, 1 they differ, 2 "
              "not a trial folder or a file that cannot be parsed");
  diff_cmd->add_option("run_a", diff.run_a, "Trial folder A (<out>/<trial>-<run id>)")->required();
  diff_cmd->add_option("run_b", diff.run_b, "Trial folder B")->required();
  AddJsonFlag(diff_cmd, diff.json);
  diff_cmd->footer(kDiffHelp);

  ViewArgs& view = s.view;
  auto* view_cmd = s.view_cmd = app.add_subcommand(
      "view", "Replay a trial's recording (RUN_DIR/recording.mcap) in the built-in page; Foxglove "
              "connects to the same address. Serves until Ctrl-C (exit 0)");
  view_cmd->add_option("run_dir", view.run_dir, "Trial folder (<out>/<trial>-<run id>)")->required();
  view_cmd->add_option("--addr", view.addr, "Listen on ADDR:PORT (default 127.0.0.1:8765; port 0: any free)");
}

// gc and version: the housekeeping commands.
void AddHousekeepingCommands(CLI::App& app, Subcommands& s) {
  GcArgs& gc = s.gc;
  auto* gc_cmd = s.gc_cmd = app.add_subcommand("gc", "Remove containers and networks left by killed runs");
  gc_cmd->add_option("--run", gc.run_id, "Only this run id (default: every run not alive here)");
  gc_cmd->add_flag("--dry-run", gc.dry_run, "List what would be removed; remove nothing");
  AddJsonFlag(gc_cmd, gc.json);

  s.version_cmd = app.add_subcommand("version", "Print the version, git commit and build type");
  AddJsonFlag(s.version_cmd, s.version_json);
}

int VersionCommand(bool json_out) {
  if (!json_out) {
    std::cout << swarmbox::VersionLine("swarmbox") << "\n";
    return kExitOk;
  }
  const swarmbox::BuildInfo& b = swarmbox::Build();
  swarmbox::yaml::Node o = swarmbox::yaml::Node::Mapping();
  o.Set("version", json::Str(b.version));
  o.Set("commit", json::Str(b.commit));
  o.Set("build_type", json::Str(b.build_type));
  json::Print(o);
  return kExitOk;
}

// The one subcommand given (require_subcommand(1)).
int Dispatch(Subcommands& s) {
  if (*s.run_cmd) {
    s.run.view_requested = s.run_cmd->count("--view") > 0;
    return RunCommand(s.run);
  }
  if (*s.validate_cmd) return ValidateCommand(s.validate);
  if (*s.compose_cmd) return ComposeCommand(s.compose);
  if (*s.images_cmd) {
    s.images.faults = !s.no_faults;
    return ImagesCommand(s.images);
  }
  if (*s.exp_cmd) return ExperimentCommand(s.exp);
  if (*s.report_cmd) return ReportCommand(s.report);
  if (*s.diff_cmd) return DiffCommand(s.diff);
  if (*s.view_cmd) return ViewCommand(s.view);
  if (*s.gc_cmd) return GcCommand(s.gc);
  if (*s.version_cmd) return VersionCommand(s.version_json);
  return kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"SwarmBox: a containerised SITL fleet for a search-and-rescue drone swarm.\n" +
                   swarmbox::VersionLine("swarmbox"),
               "swarmbox"};
  app.footer(kExitCodes);
  app.set_version_flag("--version", swarmbox::VersionLine("swarmbox"),
                       "Print the version, git commit and build type, and exit");
  app.require_subcommand(1);
  Subcommands s;
  AddRunCommand(app, s);
  AddValidateCommand(app, s);
  AddComposeCommand(app, s);
  AddImagesCommand(app, s);
  AddExperimentCommand(app, s);
  AddFolderCommands(app, s);
  AddHousekeepingCommands(app, s);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  return Dispatch(s);
}
