// swarmbox-fit-thermal: fits how the agent takes the thermal camera's evidence into the colour
// detector's confidence (agent/swarm thermal_evidence.hpp), on the shipped detector's own
// candidates in rendered training worlds, and writes it with its provenance (the `fit-thermal`
// target: agent/swarm/models/thermal_evidence.yaml).
//
//   swarmbox-fit-thermal --out FILE [--seed N (9001)] [--scenes N (2880; 0 with --replay)]
//                        [--radius-m R (0.7)] [--min-altitude M (15)] [--max-altitude M (35)]
//                        [--near-victims F (0.75)] [--near-distractors F (0)] [--replay DIR]
//                        [--evaluate DIR (the AUCs on other flown trials' frames: Evaluate)]
//                        [--samples CSV (every candidate: logit, contrast_k, person, altitude_m, x_m, y_m)]
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
// contrast, 1) by Newton's method: the fused confidence is its probability. Refused seeds: the
// perception bench's evaluation seeds and the shipped model's training and calibration seeds.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "perception_scenes.hpp"
#include "swarmbox/physics/thermal_renderer.hpp"
#include "swarmbox/swarm/geolocation.hpp"
#include "swarmbox/swarm/thermal_evidence.hpp"
#include "swarmbox/swarm/victim_detector.hpp"
#include "swarmbox/swarm/victim_detector_model.hpp"

namespace {

using namespace swarmbox;
using Eigen::Vector3d;

struct Sample {
  double logit;       // the colour detector's, clamped to +-12
  double contrast_k;  // clamped as Fuse clamps it
  bool person;
  double altitude_m;  // the scene's camera height
  double x_m, y_m;    // where the candidate was placed on the ground
};

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
    // Solve h d = g (Gaussian elimination, N <= 3).
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

// The candidates of one scene as samples.
void AddSamples(const perception_scenes::Scene& s, swarm::VictimDetector& detector, double radius_m,
                std::vector<Sample>* out) {
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
    out->push_back({std::clamp(std::log(p / (1 - p)), -12.0, 12.0),
                    std::clamp(*c, swarm::kMinContrastK, swarm::kMaxContrastK), near != nullptr, s.altitude_m,
                    g->x(), g->y()});
  }
}

int Usage() {
  std::fprintf(
      stderr,
      "usage: swarmbox-fit-thermal --out FILE [--seed N] [--scenes N] [--radius-m R] [--min-altitude M]\n"
      "         [--max-altitude M] [--near-victims F] [--near-distractors F] [--replay DIR] [--evaluate "
      "DIR]\n"
      "         [--samples CSV]\n");
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
};

std::optional<Args> ParseArgs(int argc, char** argv) {
  Args args;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) return std::nullopt;
    const std::string v = argv[++i];
    if (a == "--out") {
      args.out = v;
    } else if (a == "--seed") {
      args.seed = std::strtoull(v.c_str(), nullptr, 10);
    } else if (a == "--scenes") {
      args.scenes = std::atoi(v.c_str());
    } else if (a == "--radius-m") {
      args.radius_m = std::atof(v.c_str());
    } else if (a == "--near-distractors") {
      args.near_distractors = std::atof(v.c_str());
    } else if (a == "--near-victims") {
      args.near_victims = std::atof(v.c_str());
    } else if (a == "--min-altitude") {
      args.min_altitude_m = std::atof(v.c_str());
    } else if (a == "--max-altitude") {
      args.max_altitude_m = std::atof(v.c_str());
    } else if (a == "--evaluate") {
      args.evaluate = v;
    } else if (a == "--replay") {
      args.replay = v;
    } else if (a == "--samples") {
      args.samples = v;
    } else {
      return std::nullopt;
    }
  }
  if (args.out.empty() || (args.scenes < 24 && !(args.scenes == 0 && !args.replay.empty())) ||
      !(args.radius_m > 0.1 && args.radius_m < 3) ||
      !(args.near_distractors >= 0 && args.near_distractors <= 1) ||
      !(args.near_victims >= 0 && args.near_victims <= 1) ||
      !(args.min_altitude_m > 0 && args.min_altitude_m <= args.max_altitude_m))
    return std::nullopt;
  return args;
}

// The fit's file (thermal_evidence.hpp's mapping, with its provenance); false when it cannot be written.
bool WriteFit(const Args& args, const std::array<double, 3>& w, std::size_t people, std::size_t others,
              double loss, double loss_colour, const std::vector<double>& pc, const std::vector<double>& nc) {
  std::ofstream f(args.out);
  f << "# How the agent takes the thermal camera's evidence into the colour detector's confidence\n"
    << "# (agent/swarm thermal_evidence.hpp): sigmoid(colour_weight logit(confidence) + slope_per_k c\n"
    << "# + bias), c the contrast within radius_m of the candidate's ground point. Written by\n"
    << "# swarmbox-fit-thermal (the fit-thermal target; tools/train_detector/fit_thermal_main.cpp has\n"
    << "# the method): do not edit. fit: the candidates it was fitted on, and the log-loss with the\n"
    << "# contrast and with the colour detector's confidence alone (refitted likewise).\n"
    << "thermal_evidence:\n";
  char line[768];
  std::snprintf(line, sizeof line,
                "  colour_weight: %.6f\n  slope_per_k: %.6f\n  bias: %.6f\n  radius_m: %.3f\n", w[0], w[1],
                w[2], args.radius_m);
  f << line;
  std::snprintf(
      line, sizeof line,
      "  fit: {seed: %llu, scenes: %d, altitudes_m: [15, 35], people: %zu, others: %zu, log_loss: %.4f,\n"
      "        log_loss_colour_alone: %.4f, person_contrast_p10_k: %.2f, person_contrast_p50_k: %.2f,\n"
      "        other_contrast_p50_k: %.2f, other_contrast_p90_k: %.2f}\n",
      static_cast<unsigned long long>(args.seed), args.scenes, people, others, loss, loss_colour,
      Quantile(pc, 0.1), Quantile(pc, 0.5), Quantile(nc, 0.5), Quantile(nc, 0.9));
  f << line;
  if (!args.replay.empty())
    f << "  # and the frames of the flown trials in " << args.replay << " (--replay)\n";
  return static_cast<bool>(f);
}

// The candidates as CSV, one a line; false when the file cannot be written.
bool WriteSamples(const std::string& path, const std::vector<Sample>& samples) {
  std::ofstream f(path);
  f << "logit,contrast_k,person,altitude_m,x_m,y_m\n";
  char line[160];
  for (const Sample& s : samples) {
    std::snprintf(line, sizeof line, "%.4f,%.3f,%d,%.2f,%.2f,%.2f\n", s.logit, s.contrast_k, s.person ? 1 : 0,
                  s.altitude_m, s.x_m, s.y_m);
    f << line;
  }
  return static_cast<bool>(f);
}

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
            AddSamples(f.scene, detector, args.radius_m, &per_trial[i]);
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
    for (const perception_scenes::Scene& s : *scenes) AddSamples(s, detector, args.radius_m, &samples);
  }
  if (!args.replay.empty() && !ReplaySamples(args, args.replay, &samples)) return std::nullopt;
  return samples;
}

// The area under the ROC curve of `score` over the samples `keep` selects (ties count half).
template <typename Score, typename Keep>
double Auc(const std::vector<Sample>& samples, Score score, Keep keep) {
  std::vector<std::pair<double, bool>> v;
  for (const Sample& s : samples) {
    if (keep(s)) v.emplace_back(score(s), s.person);
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

// --evaluate DIR: how well each score ranks people over the other candidates on the flown trials'
// own frames, at the search altitude (views from 24 m up) and in the close looks (below), one
// line per band and score: the colour confidence alone, the contrast alone, the shipped fusion
// and this fit.
bool Evaluate(const Args& args, const std::array<double, 3>& w) {
  std::vector<Sample> samples;
  if (!ReplaySamples(args, args.evaluate, &samples)) return false;
  // The shipped fit from the source tree (this tool builds before the agent embeds it).
  Result<yaml::Node> doc = yaml::ParseFile(SWARMBOX_THERMAL_EVIDENCE_FILE);
  Result<swarm::ThermalEvidence> shipped =
      doc ? swarm::ParseThermalEvidence(*doc) : Result<swarm::ThermalEvidence>(doc.error());
  if (!shipped) {
    std::fprintf(stderr, "swarmbox-fit-thermal: the shipped fit: %s\n", shipped.error().ToString().c_str());
    return false;
  }
  const swarm::ThermalEvidence fit{w[0], w[1], w[2], args.radius_m};
  const auto fused = [](const swarm::ThermalEvidence& e) {
    return [e](const Sample& s) { return e.Fuse(1.0 / (1.0 + std::exp(-s.logit)), s.contrast_k); };
  };
  const auto colour = [](const Sample& s) { return s.logit; };
  const auto contrast = [](const Sample& s) { return s.contrast_k; };
  for (const bool close : {false, true}) {
    const auto keep = [close](const Sample& s) { return (s.altitude_m < 24.0) == close; };
    const auto people =
        std::count_if(samples.begin(), samples.end(), [&](const Sample& s) { return keep(s) && s.person; });
    const auto all = std::count_if(samples.begin(), samples.end(), keep);
    std::printf(
        "evaluate=%s band=%s people=%td others=%td auc_colour=%.3f auc_contrast=%.3f auc_shipped=%.3f "
        "auc_fit=%.3f\n",
        args.evaluate.c_str(), close ? "close" : "search", people, all - people, Auc(samples, colour, keep),
        Auc(samples, contrast, keep), Auc(samples, fused(*shipped), keep), Auc(samples, fused(fit), keep));
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Args> args = ParseArgs(argc, argv);
  if (!args) return Usage();
  const std::optional<std::vector<Sample>> samples = Candidates(*args);
  if (!samples) return 1;
  if (!args->samples.empty() && !WriteSamples(args->samples, *samples)) {
    std::fprintf(stderr, "swarmbox-fit-thermal: cannot write %s\n", args->samples.c_str());
    return 1;
  }
  std::vector<double> pc, nc;
  for (const Sample& s : *samples) (s.person ? pc : nc).push_back(s.contrast_k);
  if (pc.size() < 20 || nc.size() < 20) {
    std::fprintf(stderr, "swarmbox-fit-thermal: too few candidates (%zu people, %zu others)\n", pc.size(),
                 nc.size());
    return 1;
  }
  auto both = [](const Sample& s) { return std::array<double, 3>{s.logit, s.contrast_k, 1.0}; };
  auto colour = [](const Sample& s) { return std::array<double, 2>{s.logit, 1.0}; };
  const std::array<double, 3> w = Fit<3>(*samples, both);
  const std::array<double, 2> w_colour = Fit<2>(*samples, colour);
  if (!(w[0] > 0 && w[1] > 0)) {
    std::fprintf(stderr, "swarmbox-fit-thermal: the fit's weights are %g, %g: not a usable fusion\n", w[0],
                 w[1]);
    return 1;
  }
  const double loss = LogLoss<3>(*samples, w, both), loss_colour = LogLoss<2>(*samples, w_colour, colour);
  if (!WriteFit(*args, w, pc.size(), nc.size(), loss, loss_colour, pc, nc)) {
    std::fprintf(stderr, "swarmbox-fit-thermal: cannot write %s\n", args->out.c_str());
    return 1;
  }
  std::printf(
      "fit=thermal seed=%llu scenes=%d people=%zu others=%zu colour_weight=%.4f slope_per_k=%.4f bias=%.4f "
      "log_loss=%.4f log_loss_colour_alone=%.4f\n",
      static_cast<unsigned long long>(args->seed), args->scenes, pc.size(), nc.size(), w[0], w[1], w[2], loss,
      loss_colour);
  if (!args->evaluate.empty() && !Evaluate(*args, w)) return 1;
  return 0;
}
