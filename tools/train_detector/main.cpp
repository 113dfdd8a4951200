// swarmbox-train-detector: trains the victim detector and writes the model and its report.
//
//   swarmbox-train-detector --out-dir agent/swarm/models
//   (the build runs it: cmake --build build --target train-detector)
//   swarmbox-train-detector --out-dir agent/swarm/models --recalibrate
//   (steps 4-5 only, on the model in --out-dir: the sigmoid and the figures; the JSON keeps the
//   training lines and gets "recalibrated": true)
//   swarmbox-train-detector --out-dir DIR --recalibrate --replace-cnn FILE.onnx
//   (the same with another CNN in place of the model's: train_cnn.py run again on its patches)
//   swarmbox-train-detector --out-dir DIR --recalibrate --close-cnn FILE.onnx --close-cnn-patch-px 64
//     --close-calibration-altitude 18 ...
//   (the same, and FILE.onnx becomes the model's close-look CNN, the close sigmoid fitted to it:
//   the train-close-cnn target's last step, with the CNN of the close-view model it trains first)
//   --model-name NAME: DIR/NAME.yml.gz and DIR/NAME.json (default victim_detector; e.g.
//   victim_detector_close for one trained with --view-altitudes 10,20 --cnn-patch-px 48)
//   Recipe options (the defaults are the shipped model's recipe; README.md "Another recipe"):
//   --training-sets N (seeds 7000001..7000000+N), --trees N, --max-negatives N,
//   --stage1-percentile P, --balance-classes, --hard-negative-rounds N, --blob-features,
//   --negatives-sets N (cones-and-rubble sets 7200001..7200000+N), --world-sets N (generated
//   rubble fields 7300001..7300000+N), --world-distractors N (in each of those fields;
//   default 25), --stage1-rounds N (stage 1's hard negatives), --calibration-altitude M
//   (calibration frames at M +- 3 m; with --recalibrate: refit the sigmoid there),
//   --close-calibration-altitude M (a second sigmoid, fitted at M +- 3 m, for finer frames: close
//   looks; --recalibrate without it drops a model's), --calibration-sets N
//   (calibration seeds 7100001..7100000+N; default 2), --clean-calibration (no painted clutter on the
//   calibration frames), --max-candidates N
//   (the first stage's cap while calibrating and mining), --operating-precision P (probability 0.5
//   where the calibration detections reach precision P), --export-patches FILE (the CNN's patches,
//   train_detector.hpp), --cnn SCRIPT (a CNN second stage trained by SCRIPT, train_cnn.py, with
//   --python PY, its ONNX at --cnn-onnx FILE (default DIR/victim_detector_cnn.onnx; the patches
//   beside it unless --export-patches), --cnn-epochs N, --cnn-seed N, --cnn-widths A,B,C (its
//   three blocks' channels), --cnn-negatives N (negatives drawn per epoch), --cnn-hard-fraction F
//   (the share of them drawn from the hardest the network scores), --cnn-patch-px N (its patch side
//   over 3 m; default 32), --cnn-symmetries N (1, 4 or 8: each patch scored in that many of the
//   square's symmetries, the logits averaged; with --recalibrate it replaces the model's),
//   --view-altitudes LO,HI (every training set's heights))
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
  std::string model_name = "victim_detector";  // DIR/NAME.yml.gz and DIR/NAME.json
  bool recalibrate = false;
  td::TrainingOptions options = td::DefaultTrainingOptions();
};

constexpr int kContinue = -1;  // ParseArgs: no exit yet

constexpr int kUsageError = 2;

// --training-sets N: the seeds 7000001..7000000+N.
bool SetTrainingSets(const char* value, Args* args) {
  const int n = std::stoi(value);
  if (n < 1 || n > 99) {
    std::fprintf(stderr, "swarmbox-train-detector: --training-sets must be 1..99\n");
    return false;
  }
  args->options.training_seeds = td::SeedSets(td::kTrainingSeedBase, n);
  return true;
}

// --calibration-sets N: the calibration seeds 7100001..7100000+N.
bool SetCalibrationSets(const char* value, Args* args) {
  const int n = std::stoi(value);
  if (n < 1 || n > 99) {
    std::fprintf(stderr, "swarmbox-train-detector: --calibration-sets must be 1..99\n");
    return false;
  }
  args->options.calibration_seeds = td::SeedSets(td::kCalibrationSeedBase, n);
  return true;
}

// --view-altitudes LO,HI: every training set's views between LO and HI metres.
bool SetViewAltitudes(const char* value, Args* args) {
  const std::string text = value;
  const std::size_t comma = text.find(',');
  if (comma == std::string::npos) {
    std::fprintf(stderr, "swarmbox-train-detector: --view-altitudes takes LO,HI (metres)\n");
    return false;
  }
  args->options.view_min_altitude_m = std::stod(text.substr(0, comma));
  args->options.view_max_altitude_m = std::stod(text.substr(comma + 1));
  return true;
}

// A flag: its name, whether a value follows it, and what it sets (false: a usage error, printed).
struct Flag {
  std::string_view name;
  bool takes_value;
  bool (*apply)(const char* value, Args* args);
};

constexpr Flag kFlags[] = {
    {"--out-dir", true, [](const char* v, Args* a) { a->out_dir = v; return true; }},
    {"--recalibrate", false, [](const char*, Args* a) { a->recalibrate = true; return true; }},
    {"--scenes-per-set", true, [](const char* v, Args* a) { a->options.scenes_per_set = std::stoi(v); return true; }},
    {"--training-sets", true, SetTrainingSets},
    {"--trees", true, [](const char* v, Args* a) { a->options.forest_trees = std::stoi(v); return true; }},
    {"--max-negatives", true, [](const char* v, Args* a) { a->options.max_negatives = std::stoi(v); return true; }},
    {"--stage1-percentile", true, [](const char* v, Args* a) { a->options.stage1_percentile = std::stod(v); return true; }},
    {"--balance-classes", false, [](const char*, Args* a) { a->options.balance_classes = true; return true; }},
    {"--hard-negative-rounds", true,
     [](const char* v, Args* a) { a->options.hard_negative_rounds = std::stoi(v); return true; }},
    {"--blob-features", false, [](const char*, Args* a) { a->options.blob_features = true; return true; }},
    {"--negatives-sets", true, [](const char* v, Args* a) { a->options.negatives_sets = std::stoi(v); return true; }},
    {"--stage1-rounds", true, [](const char* v, Args* a) { a->options.stage1_rounds = std::stoi(v); return true; }},
    {"--world-distractors", true,
     [](const char* v, Args* a) { a->options.world_distractors = std::stoi(v); return true; }},
    {"--world-sets", true, [](const char* v, Args* a) { a->options.world_sets = std::stoi(v); return true; }},
    {"--max-candidates", true, [](const char* v, Args* a) { a->options.max_candidates = std::stoi(v); return true; }},
    {"--operating-precision", true,
     [](const char* v, Args* a) { a->options.operating_precision = std::stod(v); return true; }},
    {"--calibration-altitude", true,
     [](const char* v, Args* a) { a->options.calibration_altitude_m = std::stod(v); return true; }},
    {"--calibration-sets", true, SetCalibrationSets},
    {"--clean-calibration", false, [](const char*, Args* a) { a->options.clean_calibration = true; return true; }},
    {"--export-patches", true, [](const char* v, Args* a) { a->options.export_patches = v; return true; }},
    {"--cnn", true, [](const char* v, Args* a) { a->options.cnn_script = v; return true; }},
    {"--python", true, [](const char* v, Args* a) { a->options.python = v; return true; }},
    {"--cnn-onnx", true, [](const char* v, Args* a) { a->options.cnn_onnx_out = v; return true; }},
    {"--cnn-epochs", true, [](const char* v, Args* a) { a->options.cnn_epochs = std::stoi(v); return true; }},
    {"--cnn-seed", true, [](const char* v, Args* a) { a->options.cnn_seed = std::stoi(v); return true; }},
    {"--cnn-widths", true, [](const char* v, Args* a) { a->options.cnn_widths = v; return true; }},
    {"--cnn-negatives", true,
     [](const char* v, Args* a) { a->options.cnn_negatives_per_epoch = std::stoi(v); return true; }},
    {"--cnn-hard-fraction", true,
     [](const char* v, Args* a) { a->options.cnn_hard_fraction = std::stod(v); return true; }},
    {"--cnn-patch-px", true, [](const char* v, Args* a) { a->options.cnn_patch_px = std::stoi(v); return true; }},
    {"--close-calibration-altitude", true,
     [](const char* v, Args* a) { a->options.close_calibration_altitude_m = std::stod(v); return true; }},
    {"--cnn-symmetries", true,
     [](const char* v, Args* a) { a->options.cnn_symmetries = std::stoi(v); return true; }},
    {"--view-altitudes", true, SetViewAltitudes},
    {"--model-name", true, [](const char* v, Args* a) { a->model_name = v; return true; }},
    {"--replace-cnn", true, [](const char* v, Args* a) { a->options.replace_cnn = v; return true; }},
    {"--close-cnn", true, [](const char* v, Args* a) { a->options.close_cnn = v; return true; }},
    {"--close-cnn-patch-px", true,
     [](const char* v, Args* a) { a->options.close_cnn_patch_px = std::stoi(v); return true; }},
};

// The flag named `a` when it is complete at argv[i] (its value, if it takes one, follows).
const Flag* FindFlag(std::string_view a, int i, int argc) {
  for (const Flag& f : kFlags) {
    if (a == f.name && (!f.takes_value || i + 1 < argc)) return &f;
  }
  return nullptr;
}

// The flags into *args; an exit code for a usage error.
int ParseArgs(int argc, char** argv, Args* args) {
  for (int i = 1; i < argc; ++i) {
    const Flag* flag = FindFlag(argv[i], i, argc);
    if (flag == nullptr) {
      std::fprintf(stderr,
                   "usage: swarmbox-train-detector --out-dir DIR [--recalibrate] [--scenes-per-set N] "
                   "[--training-sets N] [--trees N] [--max-negatives N] [--stage1-percentile P] "
                   "[--balance-classes] [--hard-negative-rounds N] [--blob-features] [--negatives-sets N] [--world-sets N] [--world-distractors N] [--stage1-rounds N] "
                   "[--calibration-altitude M] [--close-calibration-altitude M] [--calibration-sets N] [--clean-calibration] [--max-candidates N] "
                   "[--operating-precision P] [--export-patches FILE] "
                   "[--cnn train_cnn.py [--python PY] [--cnn-onnx FILE] [--cnn-epochs N] [--cnn-seed N] "
                   "[--cnn-widths A,B,C] [--cnn-negatives N] [--cnn-hard-fraction F] [--cnn-patch-px N] "
                   "[--cnn-symmetries 1|4|8]] "
                   "[--view-altitudes LO,HI] [--model-name NAME] "
                   "[--recalibrate --replace-cnn FILE] "
                   "[--recalibrate --close-cnn FILE [--close-cnn-patch-px N] --close-calibration-altitude M]\n");
      return kUsageError;
    }
    const char* value = flag->takes_value ? argv[++i] : nullptr;
    if (!flag->apply(value, args)) return kUsageError;
  }
  if (args->out_dir.empty()) {
    std::fprintf(stderr, "swarmbox-train-detector: --out-dir is required\n");
    return kUsageError;
  }
  if ((!args->options.replace_cnn.empty() || !args->options.close_cnn.empty()) && !args->recalibrate) {
    std::fprintf(stderr, "swarmbox-train-detector: --replace-cnn and --close-cnn go with --recalibrate\n");
    return kUsageError;
  }
  if (args->options.cnn_onnx_out.empty()) args->options.cnn_onnx_out = args->out_dir + "/" + args->model_name + "_cnn.onnx";
  return kContinue;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The training lines of the old report, the calibration lines (and the recipe, which names the
// calibration's options) of the new one.
std::string MergeRecalibratedReport(const std::string& old_json, const std::string& text) {
  std::istringstream old_lines(old_json), new_lines(text);
  std::string line, merged;
  auto calibration_line = [](const std::string& l) {
    return l.find("\"recipe\"") != std::string::npos || l.find("\"platt\"") != std::string::npos ||
           l.find("\"calibration_figures\"") != std::string::npos ||
           l.find("\"stage1_calibration_recall\"") != std::string::npos;
  };
  std::string fresh;
  while (std::getline(new_lines, line)) {
    if (calibration_line(line)) fresh += line + "\n";
  }
  while (std::getline(old_lines, line)) {
    if (calibration_line(line) || line.find("\"recalibrated\"") != std::string::npos) continue;
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
  const std::string model_path = args.out_dir + "/" + args.model_name + ".yml.gz";
  const std::string json_path = args.out_dir + "/" + args.model_name + ".json";
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
  std::string text = td::ReportJson(*model, options, report, args.model_name + ".yml.gz");
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
