// swarmbox report DIR: regenerates DIR/results.csv, DIR/report.html, DIR/plots/ and each trial's
// plots.html from the trial folders (experiment_runner.hpp WriteReports). Exit 2 when DIR is not a folder or holds
// no trial.
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "swarmbox/experiment/experiment_runner.hpp"

namespace swarmbox::cli {

int ReportCommand(const ReportArgs& args) {
  std::error_code ec;
  if (!std::filesystem::is_directory(args.dir, ec)) {
    std::cerr << "swarmbox report: " << args.dir << " is not a folder\n";
    return kExitUsage;
  }
  std::vector<std::string> problems;
  auto n = experiment::WriteReports(args.dir, &problems);
  for (const std::string& p : problems) std::cerr << "  note: " << p << "\n";
  if (!n) {
    std::cerr << "swarmbox report: " << n.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  if (*n == 0) {
    std::cerr << "swarmbox report: no trial folder (with result.json) in " << args.dir << "\n";
    return kExitUsage;
  }
  std::cout << args.dir << "/results.csv, " << args.dir << "/report.html, " << args.dir
            << "/plots/, <trial>/plots.html: " << *n << " trials\n";
  return kExitOk;
}

}  // namespace swarmbox::cli
