// swarmbox-fit-thermal: fits how the agent takes the thermal camera's evidence into the colour
// detector's confidence (agent/swarm thermal_evidence.hpp), on the shipped detector's own
// candidates in rendered training worlds, and writes it with its provenance (the `fit-thermal`
// target: agent/swarm/models/thermal_evidence.yaml).
//
//   swarmbox-fit-thermal --out FILE [--seed N (9001)] [--scenes N (2880; 0 with --replay)]
//                        [--radius-m R (0.7)] [--min-altitude M (15)] [--max-altitude M (35)]
//                        [--near-victims F (0.75)] [--near-distractors F (0)] [--replay DIR]
//                        [--evaluate DIR (the AUCs on other flown trials' frames: Evaluate)]
//                        [--samples CSV (every candidate: logit, contrast_k, person, altitude_m, x_m, y_m,
//                         cnn_logit)]
//                        [--cnn train_thermal_cnn.py --cnn-work DIR [--cnn-epochs N (12)]
//                         [--cnn-seed N (1)] [--python PATH (/usr/bin/python3)] [--thermal-views N (0)]]
//
// --replay DIR adds the candidates on flown trials' own frames (DIR: a trial folder or an
// experiment's; perception_scenes::ReplayTrial renders each scout's colour and thermal frames
// along truth.csv, the close looks' hover frames too): the mission's altitudes, tilts, motion
// blur and the look-alikes its search flags (trials/experiments/rubble_cal.yaml flies fields
// rubble20 never scores). --near-distractors F centres that share of the views not near a person
// near a distractor instead (the look-alikes a close look meets).
//
// Scenes: nadir views from 15-35 m (the close look's 18 m to above the search's 30 m) of rubble
// fields as trials/sar_rubble.yaml generates them (perception_scenes.hpp, SarRubbleSpec; 24 views
// a world, most near a person), each with the x500's thermal frame (trials/airframes/x500.yaml
// `thermal:`, the physics server's ThermalRenderer). The shipped detector runs on each colour frame;
// each candidate is placed on the ground with the true pose and labelled a person when within
// 1.5 m of one at least half visible (near one less visible: left out), else not; its contrast is
// ThermalContrastAt's (the agent's own code), candidates the thermal frame does not see are left
// out. The fit: a logistic regression of person-or-not on (logit of the detector's confidence,
// contrast, 1) by Newton's method: the fused confidence is its probability.
//
// --thermal-views N (with --cnn): the classifier also trains on the patches of N thermal frames of
// generated rubble fields at every person, distractor and some ground points in them
// (perception_scenes::RenderThermalPatches: far more people and look-alikes, in more surroundings,
// than the colour detector's candidates hold); the fusion is not fitted on them.
//
// --cnn SCRIPT: the thermal classifier too (thermal_evidence.hpp ThermalClassifier). Each
// candidate's thermal patch (ThermalPatchAt, the agent's own code) goes into DIR/thermal_patches.bin,
// split by world or trial (every fourth one the calibration split, Calibration); the script
// (train_thermal_cnn.py, torch) trains the network on the training split and writes it into DIR;
// every candidate is scored by it through cv::dnn, and the fusion's regression on (logit,
// contrast, the network's logit, 1) is fitted on the calibration split alone (candidates the
// network never saw; a term whose weight fits <= 0 dropped); the network is copied beside --out as
// thermal_cnn.onnx once the fit is usable. Refused seeds: the perception bench's evaluation seeds
// and the shipped model's training and calibration seeds.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <spawn.h>
#include <sys/wait.h>

#include <opencv2/core.hpp>

#include "perception_scenes.hpp"
#include "swarmbox/physics/thermal_renderer.hpp"
#include "swarmbox/swarm/geolocation.hpp"
#include "swarmbox/swarm/thermal_evidence.hpp"
#include "swarmbox/swarm/victim_detector.hpp"
#include "swarmbox/swarm/victim_detector_model.hpp"

extern char** environ;

namespace {

using namespace swarmbox;
using Eigen::Vector3d;

struct Sample {
  double logit;       // the colour detector's, clamped to +-12
  double contrast_k;  // clamped as Fuse clamps it
  bool person;
  double altitude_m;  // the scene's camera height
  double x_m, y_m;    // where the candidate was placed on the ground
  int group = 0;      // its world (scenes) or trial (replays): the CNN's split (Calibration)
  std::vector<float> patch;  // ThermalPatchAt's (empty: not in the frame)
  double cnn_logit = 0.0;    // the thermal classifier's on it (0 without one, as the agent takes it)
  bool thermal_only = false;  // --thermal-views: a patch of a thermal frame alone (no colour
                              // candidate): the classifier trains on it, the fusion does not fit on it
};

// The calibration split: every fourth world or trial, never trained on by the thermal CNN; the
// fusion with the CNN is fitted on it alone.
bool Calibration(const Sample& s) { return s.group % 4 == 3; }

// Logistic regression on the features `f(sample)` (the last one the intercept) by Newton's method.
template <std::size_t N, typename F>
std::array<double, N> Fit(const std::vector<Sample>& samples, F features) {
  std::array<double, N> w{};
  for (int it = 0; it < 100; ++it) {
    std::array<double, N> g{};
    std::array<std::array<double, N>, N> h{};
    for (const Sample& s : samples) {
      const std::array<double, N> x = features(s);
      double z = 0;
      for (std::size_t i = 0; i < N; ++i) z += w[i] * x[i];
      const double p = 1.0 / (1.0 + std::exp(-z)), y = s.person ? 1.0 : 0.0;
      for (std::size_t i = 0; i < N; ++i) {
        g[i] += (p - y) * x[i];
        for (std::size_t j = 0; j < N; ++j) h[i][j] += p * (1 - p) * x[i] * x[j] + (i == j ? 1e-9 : 0.0);
      }
    }
    // Solve h d = g (Gaussian elimination, N <= 4).
    std::array<std::array<double, N + 1>, N> m{};
    for (std::size_t i = 0; i < N; ++i) {
      for (std::size_t j = 0; j < N; ++j) m[i][j] = h[i][j];
      m[i][N] = g[i];
    }
    for (std::size_t c = 0; c < N; ++c) {
      for (std::size_t r = c + 1; r < N; ++r) {
        const double k = m[r][c] / m[c][c];
        for (std::size_t j = c; j <= N; ++j) m[r][j] -= k * m[c][j];
      }
    }
    std::array<double, N> d{};
    for (std::size_t c = N; c-- > 0;) {
      double v = m[c][N];
      for (std::size_t j = c + 1; j < N; ++j) v -= m[c][j] * d[j];
      d[c] = v / m[c][c];
    }
    double step = 0;
    for (std::size_t i = 0; i < N; ++i) w[i] -= d[i], step = std::max(step, std::abs(d[i]));
    if (step < 1e-10) break;
  }
  return w;
}

template <std::size_t N, typename F>
double LogLoss(const std::vector<Sample>& samples, const std::array<double, N>& w, F features) {
  double loss = 0;
  for (const Sample& s : samples) {
    const std::array<double, N> x = features(s);
    double z = 0;
    for (std::size_t i = 0; i < N; ++i) z += w[i] * x[i];
    const double p = std::clamp(1.0 / (1.0 + std::exp(-z)), 1e-12, 1 - 1e-12);
    loss -= s.person ? std::log(p) : std::log(1 - p);
  }
  return loss / static_cast<double>(samples.size());
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

// The candidates of one scene as samples of `group`.
void AddSamples(const perception_scenes::Scene& s, swarm::VictimDetector& detector, double radius_m,
                int group, std::vector<Sample>* out) {
  const cv::Mat bgr(s.image.height_px, s.image.width_px, CV_8UC3,
                    const_cast<std::uint8_t*>(s.image.bgr.data()));
  std::vector<swarm::ImageBlob> blobs;
  detector.Detect(bgr, s.intrinsics, s.true_pose, 0.0, &blobs);
  const swarm::ThermalView view = perception_scenes::ThermalViewOf(*s.thermal);
  for (const swarm::ImageBlob& b : blobs) {
    const std::optional<Vector3d> g = swarm::PixelToGround(b.centroid_px, s.intrinsics, s.true_pose, 0.0);
    if (!g) continue;
    const perception_scenes::SceneVictim* near = nullptr;
    for (const perception_scenes::SceneVictim& v : s.victims) {
      if (v.visible_fraction > 0 && (v.position_m - g->head<2>()).norm() <= 1.5) near = &v;
    }
    if (near != nullptr && near->visible_fraction < 0.5) continue;
    const std::optional<double> c = swarm::ThermalContrastAt(view, *g, radius_m);
    if (!c) continue;
    const double p = std::clamp(b.confidence, 1e-6, 1 - 1e-6);
    Sample sample{std::clamp(std::log(p / (1 - p)), -12.0, 12.0),
                  std::clamp(*c, swarm::kMinContrastK, swarm::kMaxContrastK),
                  near != nullptr,
                  s.altitude_m,
                  g->x(),
                  g->y(),
                  group,
                  {},
                  0.0};
    if (cv::Mat patch; swarm::ThermalPatchAt(view, *g, &patch))
      sample.patch.assign(patch.begin<float>(), patch.end<float>());
    out->push_back(std::move(sample));
  }
}

int Usage() {
  std::fprintf(
      stderr,
      "usage: swarmbox-fit-thermal --out FILE [--seed N] [--scenes N] [--radius-m R] [--min-altitude M]\n"
      "         [--max-altitude M] [--near-victims F] [--near-distractors F] [--replay DIR] [--evaluate "
      "DIR]\n"
      "         [--samples CSV] [--cnn SCRIPT --cnn-work DIR [--cnn-epochs N] [--cnn-seed N] [--python "
      "PATH]\n"
      "         [--thermal-views N]]\n");
  return 2;
}

struct Args {
  std::string out;
  std::uint64_t seed = 9001;
  int scenes = 2880;
  double radius_m = 0.7;
  double near_distractors = 0.0;  // SceneSetParams::near_distractor_fraction
  double near_victims = 0.75;     // SceneSetParams::near_victim_fraction
  double min_altitude_m = 15, max_altitude_m = 35;
  std::string replay;  // --replay DIR: the flown trials' frames too (ReplaySamples)
  std::string evaluate;  // --evaluate DIR: the AUCs of the shipped fusion and the fit on these trials' frames
  std::string
      samples;  // --samples FILE: every candidate as CSV (logit, contrast_k, person, altitude_m, x_m, y_m)
  std::string cnn;       // --cnn SCRIPT: train_thermal_cnn.py, the thermal classifier (TrainCnn)
  std::string cnn_work;  // --cnn-work DIR: its patch file
  std::string python = "/usr/bin/python3";
  int cnn_epochs = 12;
  int cnn_seed = 1;
  int thermal_views = 0;  // --thermal-views N: patches of N thermal frames too (ThermalViewSamples)
};

// One option's value into `args`; false for an unknown option.
bool SetOption(const std::string& a, const std::string& v, Args* args) {
  const auto f = [&v] { return std::atof(v.c_str()); };
  const auto n = [&v] { return std::atoi(v.c_str()); };
  const std::pair<const char*, std::function<void()>> options[] = {
      {"--out", [&] { args->out = v; }},
      {"--seed", [&] { args->seed = std::strtoull(v.c_str(), nullptr, 10); }},
      {"--scenes", [&] { args->scenes = n(); }},
      {"--radius-m", [&] { args->radius_m = f(); }},
      {"--near-distractors", [&] { args->near_distractors = f(); }},
      {"--near-victims", [&] { args->near_victims = f(); }},
      {"--min-altitude", [&] { args->min_altitude_m = f(); }},
      {"--max-altitude", [&] { args->max_altitude_m = f(); }},
      {"--evaluate", [&] { args->evaluate = v; }},
      {"--replay", [&] { args->replay = v; }},
      {"--samples", [&] { args->samples = v; }},
      {"--cnn", [&] { args->cnn = v; }},
      {"--cnn-work", [&] { args->cnn_work = v; }},
      {"--python", [&] { args->python = v; }},
      {"--cnn-epochs", [&] { args->cnn_epochs = n(); }},
      {"--cnn-seed", [&] { args->cnn_seed = n(); }},
      {"--thermal-views", [&] { args->thermal_views = n(); }},
  };
  for (const auto& [name, set] : options) {
    if (a == name) {
      set();
      return true;
    }
  }
  return false;
}

std::optional<Args> ParseArgs(int argc, char** argv) {
  Args args;
  for (int i = 1; i < argc; i += 2) {
    if (i + 1 >= argc || !SetOption(argv[i], argv[i + 1], &args)) return std::nullopt;
  }
  if (args.out.empty() || (args.scenes < 24 && !(args.scenes == 0 && !args.replay.empty())) ||
      !(args.radius_m > 0.1 && args.radius_m < 3) ||
      !(args.near_distractors >= 0 && args.near_distractors <= 1) ||
      !(args.near_victims >= 0 && args.near_victims <= 1) ||
      !(args.min_altitude_m > 0 && args.min_altitude_m <= args.max_altitude_m) ||
      (!args.cnn.empty() && (args.cnn_work.empty() || args.cnn_epochs < 1)) || args.thermal_views < 0 ||
      (args.thermal_views > 0 && args.cnn.empty()))
    return std::nullopt;
  return args;
}

// What was fitted: the evidence, the candidates it was fitted on and its log-loss on them, with and
// without the thermal camera.
struct Fitted {
  swarm::ThermalEvidence evidence;
  std::size_t people = 0, others = 0;
  double loss = 0, loss_colour = 0;
  std::vector<double> person_contrast, other_contrast;
};

// The fit's file (thermal_evidence.hpp's mapping, with its provenance); false when it cannot be written.
bool WriteFit(const Args& args, const Fitted& fit) {
  const swarm::ThermalEvidence& e = fit.evidence;
  std::ofstream f(args.out);
  f << "# How the agent takes the thermal camera's evidence into the colour detector's confidence\n"
    << "# (agent/swarm thermal_evidence.hpp): sigmoid(colour_weight logit(confidence) + slope_per_k c\n"
    << "# + cnn_weight l + bias), c the contrast within radius_m of the candidate's ground point, l the\n"
    << "# thermal classifier's logit on its patch (cnn_model, beside this file). Written by\n"
    << "# swarmbox-fit-thermal (the fit-thermal target; tools/train_detector/fit_thermal_main.cpp has\n"
    << "# the method): do not edit. fit: the candidates it was fitted on (with a classifier: its\n"
    << "# calibration split, never trained on), and the log-loss with the thermal camera and with the\n"
    << "# colour detector's confidence alone (refitted likewise).\n"
    << "thermal_evidence:\n";
  char line[768];
  std::snprintf(line, sizeof line,
                "  colour_weight: %.6f\n  slope_per_k: %.6f\n  bias: %.6f\n  radius_m: %.3f\n",
                e.colour_weight, e.slope_per_k, e.bias, e.radius_m);
  f << line;
  if (e.cnn_weight > 0) {
    std::snprintf(line, sizeof line, "  cnn_weight: %.6f\n  cnn_model: %s\n", e.cnn_weight,
                  e.cnn_model.c_str());
    f << line;
  }
  std::snprintf(
      line, sizeof line,
      "  fit: {seed: %llu, scenes: %d, altitudes_m: [15, 35], people: %zu, others: %zu, log_loss: %.4f,\n"
      "        log_loss_colour_alone: %.4f, person_contrast_p10_k: %.2f, person_contrast_p50_k: %.2f,\n"
      "        other_contrast_p50_k: %.2f, other_contrast_p90_k: %.2f}\n",
      static_cast<unsigned long long>(args.seed), args.scenes, fit.people, fit.others, fit.loss,
      fit.loss_colour, Quantile(fit.person_contrast, 0.1), Quantile(fit.person_contrast, 0.5),
      Quantile(fit.other_contrast, 0.5), Quantile(fit.other_contrast, 0.9));
  f << line;
  if (!args.replay.empty())
    f << "  # and the frames of the flown trials in "
      << std::filesystem::path(args.replay).filename().string() << " (--replay)\n";
  if (e.cnn_weight > 0)
    f << "  # the classifier: " << std::filesystem::path(args.cnn).filename().string() << " --seed "
      << args.cnn_seed << " --epochs " << args.cnn_epochs << " on the training split\n";
  return static_cast<bool>(f);
}

// Replayed trials' groups: kReplayGroup + the trial's index (scene worlds count from 0).
constexpr int kReplayGroup = 1000000;

// The trial folders of `dir` (it or its subfolders with a world.yaml and a truth.csv), in name order.
std::vector<std::filesystem::path> TrialFolders(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  const auto is_trial = [](const fs::path& p) {
    return fs::exists(p / "world.yaml") && fs::exists(p / "truth.csv");
  };
  std::vector<fs::path> trials;
  std::error_code ec;
  if (is_trial(dir)) return {dir};
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (is_trial(e.path())) trials.push_back(e.path());
  }
  std::sort(trials.begin(), trials.end());
  return trials;
}

// The candidates on the flown trials' own frames (perception_scenes::ReplayTrial: the scouts'
// colour and thermal frames along truth.csv), onto *out in trial order; the trials replayed on
// every core, a detector each (a trial's candidates do not depend on which); false and a message
// on failure.
bool ReplaySamples(const Args& args, const std::string& dir, std::vector<Sample>* out) {
  const std::vector<std::filesystem::path> trials = TrialFolders(dir);
  if (trials.empty()) {
    std::fprintf(stderr, "swarmbox-fit-thermal: %s: no trial folder (world.yaml and truth.csv)\n",
                 dir.c_str());
    return false;
  }
  std::vector<std::vector<Sample>> per_trial(trials.size());
  std::vector<std::string> errors(trials.size());
  std::atomic<std::size_t> next{0};
  const auto work = [&] {
    swarm::VictimDetector detector(swarm::ShippedDetectorModel(), swarm::VictimDetectorParams{});
    for (std::size_t i = next++; i < trials.size(); i = next++) {
      const Status st = perception_scenes::ReplayTrial(
          {.trial_dir = trials[i].string(), .thermal = true},
          [&](const physics::WorldConfig&, const perception_scenes::ReplayFrame& f) {
            AddSamples(f.scene, detector, args.radius_m, kReplayGroup + static_cast<int>(i), &per_trial[i]);
          });
      if (!st) errors[i] = st.error().ToString();
    }
  };
  std::vector<std::thread> pool(std::max(1U, std::thread::hardware_concurrency()) - 1);
  for (std::thread& t : pool) t = std::thread(work);
  work();
  for (std::thread& t : pool) t.join();
  for (std::size_t i = 0; i < trials.size(); ++i) {
    if (!errors[i].empty()) {
      std::fprintf(stderr, "swarmbox-fit-thermal: %s\n", errors[i].c_str());
      return false;
    }
    std::fprintf(stderr, "swarmbox-fit-thermal: %s: %zu candidates\n", trials[i].filename().c_str(),
                 per_trial[i].size());
    out->insert(out->end(), per_trial[i].begin(), per_trial[i].end());
  }
  return true;
}

// --thermal-views: the patches of perception_scenes::RenderThermalPatches (worlds from seed + 1,
// views from 16-32 m) as thermal-only samples, their worlds' groups after kThermalGroup; false and
// a message on failure.
constexpr int kThermalGroup = 2000000;
bool ThermalViewSamples(const Args& args, std::vector<Sample>* out) {
  Result<std::vector<perception_scenes::ThermalPatch>> patches =
      perception_scenes::RenderThermalPatches({.seed = args.seed + 1, .views = args.thermal_views});
  if (!patches) {
    std::fprintf(stderr, "swarmbox-fit-thermal: %s\n", patches.error().ToString().c_str());
    return false;
  }
  std::size_t people = 0;
  for (perception_scenes::ThermalPatch& p : *patches) {
    Sample s{0.0, 0.0, p.person, 0.0, 0.0, 0.0, kThermalGroup + p.world, std::move(p.patch), 0.0, true};
    people += p.person ? 1 : 0;
    out->push_back(std::move(s));
  }
  std::fprintf(stderr, "swarmbox-fit-thermal: %d thermal views: %zu patches (%zu people)\n",
               args.thermal_views, patches->size(), people);
  return true;
}

// The shipped detector's candidates on the rendered scenes (nullopt and a message on failure).
std::optional<std::vector<Sample>> Candidates(const Args& args) {
  const std::shared_ptr<const swarm::VictimDetectorModel> model = swarm::ShippedDetectorModel();
  std::vector<std::uint64_t> refused(std::begin(perception_scenes::kEvaluationSeeds),
                                     std::end(perception_scenes::kEvaluationSeeds));
  refused.insert(refused.end(), model->training_seeds.begin(), model->training_seeds.end());
  refused.insert(refused.end(), model->calibration_seeds.begin(), model->calibration_seeds.end());
  if (std::find(refused.begin(), refused.end(), args.seed) != refused.end()) {
    std::fprintf(
        stderr,
        "swarmbox-fit-thermal: seed %llu is an evaluation seed or the detector's own: fit on another\n",
        static_cast<unsigned long long>(args.seed));
    return std::nullopt;
  }
  perception_scenes::SceneSetParams params{.seed = args.seed,
                                           .scenes = args.scenes,
                                           .scenes_per_world = 24,
                                           .min_altitude_m = args.min_altitude_m,
                                           .max_altitude_m = args.max_altitude_m,
                                           .near_victim_fraction = args.near_victims,
                                           .near_distractor_fraction = args.near_distractors};
  params.generated = perception_scenes::SarRubbleSpec();
  params.thermal = true;
  swarm::VictimDetector detector(model, swarm::VictimDetectorParams{});
  std::vector<Sample> samples;
  if (args.scenes > 0) {
    Result<std::vector<perception_scenes::Scene>> scenes = perception_scenes::RenderScenes(params);
    if (!scenes) {
      std::fprintf(stderr, "swarmbox-fit-thermal: %s\n", scenes.error().ToString().c_str());
      return std::nullopt;
    }
    for (std::size_t i = 0; i < scenes->size(); ++i) {
      AddSamples((*scenes)[i], detector, args.radius_m, static_cast<int>(i / 24), &samples);
    }
  }
  if (!args.replay.empty() && !ReplaySamples(args, args.replay, &samples)) return std::nullopt;
  if (args.thermal_views > 0 && !ThermalViewSamples(args, &samples)) return std::nullopt;
  return samples;
}

// --cnn: the patches as train_thermal_cnn.py reads them (its docstring: SWBTHERM version 1), those
// of the calibration split marked so; false when the file cannot be written.
bool WritePatches(const std::string& path, const std::vector<Sample>& samples) {
  std::ofstream f(path, std::ios::binary);
  const auto count = static_cast<std::uint64_t>(
      std::count_if(samples.begin(), samples.end(), [](const Sample& s) { return !s.patch.empty(); }));
  const std::uint32_t version = 1, px = swarm::kThermalPatchPx;
  f.write("SWBTHERM", 8);
  f.write(reinterpret_cast<const char*>(&version), sizeof version);
  f.write(reinterpret_cast<const char*>(&px), sizeof px);
  f.write(reinterpret_cast<const char*>(&count), sizeof count);
  for (const Sample& s : samples) {
    if (s.patch.empty()) continue;
    const char label = s.person ? 1 : 0, split = Calibration(s) ? 1 : 0;
    f.put(label).put(split);
    f.write(reinterpret_cast<const char*>(s.patch.data()),
            static_cast<std::streamsize>(s.patch.size() * sizeof(float)));
  }
  return static_cast<bool>(f);
}

// Runs the training script (argv, no shell) and waits for it; false and a message on failure.
bool RunCnnScript(const Args& args, const std::string& patches, const std::string& onnx) {
  std::vector<std::string> argv_s = {args.python, args.cnn,
                                     "--patches", patches,
                                     "--out",     onnx,
                                     "--seed",    std::to_string(args.cnn_seed),
                                     "--epochs",  std::to_string(args.cnn_epochs)};
  std::vector<char*> argv;
  for (std::string& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  int status = 0;
  if (const int rc = posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ); rc != 0) {
    std::fprintf(stderr,
                 "swarmbox-fit-thermal: cannot run %s: %s (python3-torch: scripts/setup_training.sh)\n",
                 args.python.c_str(), std::strerror(rc));
    return false;
  }
  if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "swarmbox-fit-thermal: %s failed (python3-torch: scripts/setup_training.sh)\n",
                 args.cnn.c_str());
    return false;
  }
  return true;
}

std::optional<std::string> ReadWhole(const std::string& path) {
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  if (!f) return std::nullopt;
  std::string bytes(static_cast<std::size_t>(f.tellg()), '\0');
  f.seekg(0);
  if (!f.read(bytes.data(), static_cast<std::streamsize>(bytes.size()))) return std::nullopt;
  return bytes;
}

// Each sample's cnn_logit by the network `onnx` (the agent's ThermalClassifier; 0 without a patch,
// as the agent takes it); false and a message when cv::dnn cannot run it.
bool ScoreSamples(const std::string& onnx, std::vector<Sample>* samples) {
  Result<std::unique_ptr<swarm::ThermalClassifier>> c = swarm::ThermalClassifier::FromOnnx(onnx);
  if (!c) {
    std::fprintf(stderr, "swarmbox-fit-thermal: %s\n", c.error().ToString().c_str());
    return false;
  }
  for (Sample& s : *samples) {
    if (s.patch.empty()) {
      s.cnn_logit = 0.0;
      continue;
    }
    const cv::Mat patch(swarm::kThermalPatchPx, swarm::kThermalPatchPx, CV_32F, s.patch.data());
    s.cnn_logit = (*c)->Logit(patch);
  }
  return true;
}

// --cnn: trains the thermal classifier on the training split's patches (the script's ONNX into
// --cnn-work) and scores every sample with it: the ONNX, or nullopt and a message.
std::optional<std::string> TrainCnn(const Args& args, std::vector<Sample>* samples) {
  std::error_code ec;
  std::filesystem::create_directories(args.cnn_work, ec);
  const std::string patches = (std::filesystem::path(args.cnn_work) / "thermal_patches.bin").string();
  const std::string onnx_path = (std::filesystem::path(args.cnn_work) / "thermal_cnn.onnx").string();
  if (!WritePatches(patches, *samples)) {
    std::fprintf(stderr, "swarmbox-fit-thermal: cannot write %s\n", patches.c_str());
    return std::nullopt;
  }
  if (!RunCnnScript(args, patches, onnx_path)) return std::nullopt;
  std::optional<std::string> onnx = ReadWhole(onnx_path);
  if (!onnx) {
    std::fprintf(stderr, "swarmbox-fit-thermal: %s wrote no %s\n", args.cnn.c_str(), onnx_path.c_str());
    return std::nullopt;
  }
  if (!ScoreSamples(*onnx, samples)) return std::nullopt;
  return onnx;
}

// The fusion's weights on (logit, contrast, the classifier's logit, 1) into `e`, with the network
// `onnx`, and its log-loss. A term whose weight comes out <= 0 is dropped (its weight 0) and the
// rest refitted: the classifier can hold all the colour confidence or the contrast tell about
// these candidates. The classifier's own weight <= 0 (a network that adds nothing) is said on
// stderr; the caller refuses it.
double FitWithClassifier(const std::vector<Sample>& samples, const std::string& onnx,
                         swarm::ThermalEvidence* e) {
  std::array<bool, 2> use{true, true};  // the colour logit, the contrast
  for (;;) {
    auto features = [&use](const Sample& s) {
      return std::array<double, 4>{use[0] ? s.logit : 0.0, use[1] ? s.contrast_k : 0.0, s.cnn_logit, 1.0};
    };
    const std::array<double, 4> w = Fit<4>(samples, features);
    const bool drop_colour = use[0] && !(w[0] > 0), drop_contrast = use[1] && !(w[1] > 0);
    if (!drop_colour && !drop_contrast) {
      e->colour_weight = use[0] ? w[0] : 0.0, e->slope_per_k = use[1] ? w[1] : 0.0;
      e->cnn_weight = w[2], e->bias = w[3];
      e->cnn_model = "thermal_cnn.onnx";
      e->cnn_onnx = std::make_shared<const std::string>(onnx);
      if (!(w[2] > 0))
        std::fprintf(stderr,
                     "swarmbox-fit-thermal: the classifier's weight fits %g: the network adds nothing\n",
                     w[2]);
      return LogLoss<4>(samples, w, features);
    }
    use[0] = use[0] && !drop_colour, use[1] = use[1] && !drop_contrast;
  }
}

// The fusion fitted on `all` (with `onnx`: the calibration split alone, with the classifier's
// logit); nullopt and a message when too few candidates or a weight comes out unusable.
std::optional<Fitted> FitEvidence(const Args& args, const std::vector<Sample>& all,
                                  const std::optional<std::string>& onnx) {
  std::vector<Sample> samples;
  std::copy_if(all.begin(), all.end(), std::back_inserter(samples),
               [&](const Sample& s) { return !s.thermal_only && (!onnx || Calibration(s)); });
  Fitted fit;
  for (const Sample& s : samples)
    (s.person ? fit.person_contrast : fit.other_contrast).push_back(s.contrast_k);
  fit.people = fit.person_contrast.size(), fit.others = fit.other_contrast.size();
  if (fit.people < 20 || fit.others < 20) {
    std::fprintf(stderr, "swarmbox-fit-thermal: too few candidates (%zu people, %zu others)\n", fit.people,
                 fit.others);
    return std::nullopt;
  }
  auto colour = [](const Sample& s) { return std::array<double, 2>{s.logit, 1.0}; };
  fit.loss_colour = LogLoss<2>(samples, Fit<2>(samples, colour), colour);
  swarm::ThermalEvidence& e = fit.evidence;
  e.radius_m = args.radius_m;
  if (onnx) {
    fit.loss = FitWithClassifier(samples, *onnx, &e);
    if (!(e.cnn_weight > 0)) return std::nullopt;
  } else {
    auto both = [](const Sample& s) { return std::array<double, 3>{s.logit, s.contrast_k, 1.0}; };
    const std::array<double, 3> w = Fit<3>(samples, both);
    fit.loss = LogLoss<3>(samples, w, both);
    e.colour_weight = w[0], e.slope_per_k = w[1], e.bias = w[2];
  }
  if (!(e.cnn_weight > 0 || (e.colour_weight > 0 && e.slope_per_k > 0))) {
    std::fprintf(stderr, "swarmbox-fit-thermal: the fit's weights are %g, %g, %g: not a usable fusion\n",
                 e.colour_weight, e.slope_per_k, e.cnn_weight);
    return std::nullopt;
  }
  return fit;
}

// The area under the ROC curve of `scores` (one a sample) over the samples `keep` selects (ties
// count half).
template <typename Keep>
double Auc(const std::vector<Sample>& samples, const std::vector<double>& scores, Keep keep) {
  std::vector<std::pair<double, bool>> v;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (keep(samples[i])) v.emplace_back(scores[i], samples[i].person);
  }
  std::sort(v.begin(), v.end());
  double pos = 0, neg = 0, rank_sum = 0;
  for (std::size_t i = 0; i < v.size();) {
    std::size_t j = i;
    while (j < v.size() && v[j].first == v[i].first) ++j;
    const double mid_rank = 0.5 * static_cast<double>(i + j + 1);  // 1-based ranks i+1..j
    for (std::size_t k = i; k < j; ++k) {
      if (v[k].second) rank_sum += mid_rank, pos += 1;
    }
    neg += static_cast<double>(j - i);
    i = j;
  }
  neg -= pos;
  if (pos == 0 || neg == 0) return std::nan("");
  return (rank_sum - pos * (pos + 1) / 2) / (pos * neg);
}

// Each sample's fused confidence by `e` (its classifier's logits into the samples' cnn_logit);
// nullopt when the classifier does not run.
std::optional<std::vector<double>> FusedScores(const swarm::ThermalEvidence& e,
                                               std::vector<Sample>* samples) {
  if (e.cnn_weight > 0 && !ScoreSamples(*e.cnn_onnx, samples)) return std::nullopt;
  std::vector<double> out;
  for (const Sample& s : *samples) {
    out.push_back(
        e.Fuse(1.0 / (1.0 + std::exp(-s.logit)), s.contrast_k, e.cnn_weight > 0 ? s.cnn_logit : 0.0));
  }
  return out;
}

// The shipped thermal evidence from the source tree, its classifier beside it (this tool builds
// before the agent embeds them).
Result<swarm::ThermalEvidence> ShippedFromSource() {
  Result<yaml::Node> doc = yaml::ParseFile(SWARMBOX_THERMAL_EVIDENCE_FILE);
  if (!doc) return doc.error();
  Result<swarm::ThermalEvidence> e = swarm::ParseThermalEvidence(*doc);
  if (!e || e->cnn_weight == 0) return e;
  const std::filesystem::path onnx =
      std::filesystem::path(SWARMBOX_THERMAL_EVIDENCE_FILE).parent_path() / e->cnn_model;
  std::optional<std::string> bytes = ReadWhole(onnx.string());
  if (!bytes) return Error(ErrorCode::kNotFound, "cannot read " + onnx.string());
  e->cnn_onnx = std::make_shared<const std::string>(std::move(*bytes));
  return e;
}

// --evaluate DIR: how well each score ranks people over the other candidates on the flown trials'
// own frames, at the search altitude (views from 24 m up) and in the close looks (below), one
// line per band and score: the colour confidence alone, the contrast alone, this fit's thermal
// classifier alone (without one: nan), the shipped fusion and this fit.
bool Evaluate(const Args& args, const swarm::ThermalEvidence& fit) {
  std::vector<Sample> samples;
  if (!ReplaySamples(args, args.evaluate, &samples)) return false;
  Result<swarm::ThermalEvidence> shipped = ShippedFromSource();
  if (!shipped) {
    std::fprintf(stderr, "swarmbox-fit-thermal: the shipped fit: %s\n", shipped.error().ToString().c_str());
    return false;
  }
  const std::optional<std::vector<double>> shipped_p = FusedScores(*shipped, &samples);
  const std::optional<std::vector<double>> fit_p = FusedScores(fit, &samples);
  if (!shipped_p || !fit_p) return false;
  std::vector<double> colour, contrast, cnn;
  for (const Sample& s : samples) {
    colour.push_back(s.logit);
    contrast.push_back(s.contrast_k);
    cnn.push_back(fit.cnn_weight > 0 ? s.cnn_logit : std::nan(""));
  }
  for (const bool close : {false, true}) {
    const auto keep = [close](const Sample& s) { return (s.altitude_m < 24.0) == close; };
    const auto people =
        std::count_if(samples.begin(), samples.end(), [&](const Sample& s) { return keep(s) && s.person; });
    const auto all = std::count_if(samples.begin(), samples.end(), keep);
    std::printf(
        "evaluate=%s band=%s people=%td others=%td auc_colour=%.3f auc_contrast=%.3f auc_cnn=%.3f "
        "auc_shipped=%.3f "
        "auc_fit=%.3f\n",
        args.evaluate.c_str(), close ? "close" : "search", people, all - people, Auc(samples, colour, keep),
        Auc(samples, contrast, keep), fit.cnn_weight > 0 ? Auc(samples, cnn, keep) : std::nan(""),
        Auc(samples, *shipped_p, keep), Auc(samples, *fit_p, keep));
  }
  return true;
}

// --samples: the candidates as CSV, one a line, with the classifier's logit (--cnn: the new
// network's; else the shipped one's, when it has one); false and a message on failure.
bool WriteSamples(const Args& args, std::vector<Sample>* all) {
  if (args.cnn.empty()) {
    Result<swarm::ThermalEvidence> shipped = ShippedFromSource();
    if (!shipped) {
      std::fprintf(stderr, "swarmbox-fit-thermal: the shipped fit: %s\n", shipped.error().ToString().c_str());
      return false;
    }
    if (shipped->cnn_weight > 0 && !ScoreSamples(*shipped->cnn_onnx, all)) return false;
  }
  std::ofstream f(args.samples);
  f << "logit,contrast_k,person,altitude_m,x_m,y_m,cnn_logit\n";
  char line[192];
  for (const Sample& s : *all) {
    if (s.thermal_only) continue;
    std::snprintf(line, sizeof line, "%.4f,%.3f,%d,%.2f,%.2f,%.2f,%.3f\n", s.logit, s.contrast_k,
                  s.person ? 1 : 0, s.altitude_m, s.x_m, s.y_m, s.cnn_logit);
    f << line;
  }
  if (!f) std::fprintf(stderr, "swarmbox-fit-thermal: cannot write %s\n", args.samples.c_str());
  return static_cast<bool>(f);
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Args> args = ParseArgs(argc, argv);
  if (!args) return Usage();
  std::optional<std::vector<Sample>> samples = Candidates(*args);
  if (!samples) return 1;
  std::optional<std::string> onnx;
  if (!args->cnn.empty() && !(onnx = TrainCnn(*args, &*samples))) return 1;
  if (!args->samples.empty() && !WriteSamples(*args, &*samples)) return 1;
  const std::optional<Fitted> fit = FitEvidence(*args, *samples, onnx);
  if (!fit) return 1;
  // The network beside the fit only once the fit is usable: the two ship as a pair.
  const std::filesystem::path onnx_out = std::filesystem::path(args->out).parent_path() / "thermal_cnn.onnx";
  if (!WriteFit(*args, *fit) || (onnx && !(std::ofstream(onnx_out, std::ios::binary) << *onnx))) {
    std::fprintf(stderr, "swarmbox-fit-thermal: cannot write %s or %s\n", args->out.c_str(),
                 onnx_out.c_str());
    return 1;
  }
  const swarm::ThermalEvidence& e = fit->evidence;
  std::printf(
      "fit=thermal seed=%llu scenes=%d people=%zu others=%zu colour_weight=%.4f slope_per_k=%.4f "
      "cnn_weight=%.4f "
      "bias=%.4f log_loss=%.4f log_loss_colour_alone=%.4f\n",
      static_cast<unsigned long long>(args->seed), args->scenes, fit->people, fit->others, e.colour_weight,
      e.slope_per_k, e.cnn_weight, e.bias, fit->loss, fit->loss_colour);
  if (!args->evaluate.empty() && !Evaluate(*args, e)) return 1;
  return 0;
}
