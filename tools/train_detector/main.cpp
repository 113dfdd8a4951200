// swarmbox-train-detector: trains the victim detector and writes the model and its report.
//
//   swarmbox-train-detector --out-dir agent/swarm/models
//   (the build runs it: cmake --build build --target train-detector)
//   swarmbox-train-detector --out-dir agent/swarm/models --recalibrate
//   (steps 4-5 only, on the model in --out-dir: the sigmoid and the figures; the JSON keeps the
//   training lines and gets "recalibrated": true)
//   Recipe options (the defaults are the shipped model's recipe; README.md "Another recipe"):
//   --training-sets N (seeds 7000001..7000000+N), --trees N, --max-negatives N,
//   --stage1-percentile P, --balance-classes, --hard-negative-rounds N
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>

#include "train_detector.hpp"

namespace {

namespace td = swarmbox::train_detector;

struct Args {
  std::string out_dir;
  bool recalibrate = false;
  td::TrainingOptions options = td::DefaultTrainingOptions();
};

constexpr int kContinue = -1;  // ParseArgs: no exit yet

// The flags into *args; an exit code for a usage error.
int ParseArgs(int argc, char** argv, Args* args) {
  td::TrainingOptions& options = args->options;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--out-dir" && i + 1 < argc) {
      args->out_dir = argv[++i];
    } else if (a == "--recalibrate") {
      args->recalibrate = true;
    } else if (a == "--scenes-per-set" && i + 1 < argc) {
      options.scenes_per_set = std::stoi(argv[++i]);
    } else if (a == "--training-sets" && i + 1 < argc) {
      const int n = std::stoi(argv[++i]);
      if (n < 1 || n > 99) {
        std::fprintf(stderr, "swarmbox-train-detector: --training-sets must be 1..99\n");
        return 2;
      }
      options.training_seeds.clear();
      for (int k = 1; k <= n; ++k) options.training_seeds.push_back(7'000'000 + static_cast<std::uint64_t>(k));
    } else if (a == "--trees" && i + 1 < argc) {
      options.forest_trees = std::stoi(argv[++i]);
    } else if (a == "--max-negatives" && i + 1 < argc) {
      options.max_negatives = std::stoi(argv[++i]);
    } else if (a == "--stage1-percentile" && i + 1 < argc) {
      options.stage1_percentile = std::stod(argv[++i]);
    } else if (a == "--balance-classes") {
      options.balance_classes = true;
    } else if (a == "--hard-negative-rounds" && i + 1 < argc) {
      options.hard_negative_rounds = std::stoi(argv[++i]);
    } else {
      std::fprintf(stderr,
                   "usage: swarmbox-train-detector --out-dir DIR [--recalibrate] [--scenes-per-set N] "
                   "[--training-sets N] [--trees N] [--max-negatives N] [--stage1-percentile P] "
                   "[--balance-classes] [--hard-negative-rounds N]\n");
      return 2;
    }
  }
  if (args->out_dir.empty()) {
    std::fprintf(stderr, "swarmbox-train-detector: --out-dir is required\n");
    return 2;
  }
  return kContinue;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The training lines of the old report, the calibration lines of the new one.
std::string MergeRecalibratedReport(const std::string& old_json, const std::string& text) {
  std::istringstream old_lines(old_json), new_lines(text);
  std::string line, merged;
  auto calibration_line = [](const std::string& l) {
    return l.find("\"platt\"") != std::string::npos || l.find("\"calibration_figures\"") != std::string::npos ||
           l.find("\"stage1_calibration_recall\"") != std::string::npos;
  };
  std::string fresh;
  while (std::getline(new_lines, line)) {
    if (calibration_line(line)) fresh += line + "\n";
  }
  while (std::getline(old_lines, line)) {
    if (calibration_line(line)) continue;
    if (line.find("\"training_seconds\"") != std::string::npos) {
      merged += fresh + "  \"recalibrated\": true,\n";
    }
    merged += line + "\n";
  }
  return merged;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (int code = ParseArgs(argc, argv, &args); code != kContinue) return code;
  const td::TrainingOptions& options = args.options;
  td::TrainingReport report;
  const std::string model_path = args.out_dir + "/victim_detector.yml.gz";
  const std::string json_path = args.out_dir + "/victim_detector.json";
  const std::string old_json = args.recalibrate ? ReadText(json_path) : std::string();
  swarmbox::Result<swarmbox::swarm::VictimDetectorModel> model =
      args.recalibrate ? td::Recalibrate(options, model_path, &report) : td::Train(options, &report);
  if (!model) {
    std::fprintf(stderr, "swarmbox-train-detector: %s\n", model.error().ToString().c_str());
    return 1;
  }
  if (swarmbox::Status s = swarmbox::swarm::SaveDetectorModel(*model, model_path); !s) {
    std::fprintf(stderr, "swarmbox-train-detector: %s\n", s.error().ToString().c_str());
    return 1;
  }
  std::string text = td::ReportJson(*model, options, report);
  if (args.recalibrate) text = MergeRecalibratedReport(old_json, text);
  std::ofstream json(json_path);
  json << text;
  if (!json) {
    std::fprintf(stderr, "swarmbox-train-detector: cannot write %s\n", json_path.c_str());
    return 1;
  }
  std::printf("train-detector: wrote %s and %s (precision %.4f recall %.4f at 0.5 on %d calibration scenes, %.0f s)\n",
              model_path.c_str(), json_path.c_str(), report.precision, report.recall, report.calibration_scenes,
              report.seconds);
  return 0;
}
