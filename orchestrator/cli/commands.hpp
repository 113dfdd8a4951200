// The `swarmbox` subcommands (ARCHITECTURE.md "CLI", contract). Each returns the process exit
// code: 0 success, 1 a trial ended with another outcome, 2 bad input or usage, 3 infrastructure
// error (no Docker engine, image build failed), 130 / 143 `run` or `experiment` stopped by SIGINT
// (Ctrl-C) / SIGTERM, after the clean-up (interrupt.hpp).
//
// `json`: the command's summary is one JSON object on stdout (json_out.hpp) instead of its lines;
// progress and diagnostics stay on stderr.
#pragma once

#include <functional>
#include <set>
#include <string>
#include <vector>

namespace swarmbox::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitOutcome = 1;
inline constexpr int kExitUsage = 2;
inline constexpr int kExitInfrastructure = 3;
inline constexpr int kExitSigint = 130;   // 128 + SIGINT
inline constexpr int kExitSigterm = 143;  // 128 + SIGTERM

// Where the host-built programs come from (for the images).
struct ProgramPaths {
  std::string physics_bin;  // "" = search (see program_images.hpp)
  std::string agent_bin;
};

struct RunArgs {
  std::string trial;
  std::string out = "runs";
  std::vector<std::string> sets;
  std::string run_id;
  bool quiet = false;
  bool json = false;
  bool no_record = false;  // --no-record: the trial's record.enabled = false
  bool view_requested = false;  // --view given (with or without its ADDR:PORT)
  std::string view;             // its ADDR:PORT; "" = 127.0.0.1:8765
  ProgramPaths programs;
};
int RunCommand(const RunArgs& args);

// Each file is a trial or an experiment (one with `factors:` or `base:`); an experiment is
// checked with every trial it expands to.
struct ValidateArgs {
  std::vector<std::string> files;
  std::vector<std::string> sets;
  bool json = false;
};
int ValidateCommand(const ValidateArgs& args);

struct ComposeArgs {
  std::string trial;
  std::vector<std::string> sets;
  std::string output;  // "" = stdout
  std::string physics_image;  // "" = the tag the host-built binary packs to
  std::string agent_image;
  ProgramPaths programs;
};
int ComposeCommand(const ComposeArgs& args);

struct ImagesArgs {
  ProgramPaths programs;
  bool faults = true;
  bool quiet = false;
  bool json = false;
};
int ImagesCommand(const ImagesArgs& args);

struct ExperimentArgs {
  std::string experiment;
  std::string out;                  // "" = runs/<name>-<run id>
  std::vector<std::string> hosts;   // "" = the file's hosts:, else local
  bool resume = false;
  std::vector<std::string> filter;  // replaces the file's filter
  std::vector<std::string> sets;    // appended to the file's set: (factor levels still win)
  int max_attempts = 3;
  std::string run_id;
  bool quiet = false;
  bool json = false;
  ProgramPaths programs;
};
int ExperimentCommand(const ExperimentArgs& args);

struct ReportArgs {
  std::string dir;
};
int ReportCommand(const ReportArgs& args);

// The first divergence between two trial folders (report/run_diff.hpp): exit 0 identical, 1 they
// differ, 2 a folder that is not a trial folder or a file that cannot be parsed.
struct DiffArgs {
  std::string run_a;
  std::string run_b;
  bool json = false;
};
int DiffCommand(const DiffArgs& args);

// swarmbox view: replays RUN_DIR/recording.mcap in the built-in page (record::LiveServer) until
// Ctrl-C/SIGTERM (exit 0); 2 no or unreadable recording, bad --addr; 3 cannot listen there.
struct ViewArgs {
  std::string run_dir;
  std::string addr = "127.0.0.1:8765";  // ADDR:PORT; port 0 = any free one (the URL printed says)
};
int ViewCommand(const ViewArgs& args);

struct GcArgs {
  std::string run_id;  // "" = every run not alive on this machine
  bool dry_run = false;  // list what would be removed, remove nothing
  bool json = false;
};
int GcCommand(const GcArgs& args);

// Which runs `swarmbox gc` removes: only_run when given, else every labelled run that is not alive.
struct GcPlan {
  std::vector<std::string> remove;
  std::vector<std::string> skip_live;
};
GcPlan PlanGc(const std::set<std::string>& labelled_runs, const std::string& only_run,
              const std::function<bool(const std::string&)>& is_live);

}  // namespace swarmbox::cli
