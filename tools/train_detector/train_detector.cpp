#include "train_detector.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <set>
#include <sstream>

#include <spawn.h>
#include <sys/wait.h>

#include <cstring>
#include <fstream>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include "swarmbox/swarm/blob_features.hpp"
#include "swarmbox/swarm/candidate_patch.hpp"
#include "swarmbox/swarm/geolocation.hpp"
#include "swarmbox/swarm/victim_detector.hpp"

extern char** environ;

namespace swarmbox::train_detector {
namespace {

using perception_scenes::Scene;
using perception_scenes::SceneVictim;

constexpr double kMustDetectFraction = 0.5;   // "at least half visible"
constexpr double kPositiveRadiusM = 0.75;
constexpr double kNegativeRadiusM = 1.5;
constexpr int kRandomNegativesPerScene = 40;
// Stage 1's hard negatives per scene and bootstrapping round (AddStage1HardNegatives).
constexpr int kStage1HardPerScene = 16;
constexpr int kStage2CandidatesPerScene = 96;
// A window one cell (0.25 m) off a person's centre is taught a lower score than the centred one, so
// the first stage peaks on the person (geolocation) rather than anywhere on a plateau.
constexpr float kShiftedTarget = 0.3f;
// Detections of the first forest at least this sure of a person where there is none are mined as
// hard negatives for the second.
constexpr double kHardNegativeVotes = 0.2;

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}


// Ground scale at the image centre, as VictimDetector::Detect(pose) computes it.
double PixelsPerMetre(const Scene& s) {
  const std::optional<Eigen::Vector3d> c =
      swarm::PixelToGround({s.intrinsics.cx_px, s.intrinsics.cy_px}, s.intrinsics, s.true_pose, 0.0);
  const Eigen::Vector3d axis = s.true_pose.rotation * Eigen::Vector3d::UnitZ();
  const double range = c ? (*c - s.true_pose.position_m).dot(axis) : s.altitude_m;
  return s.intrinsics.fx_px / range;
}

// A person's centre in padded canonical pixels, or nothing when it does not project.
std::optional<Eigen::Vector2d> CanonicalOf(const SceneVictim& v, const Scene& s, double scale) {
  const std::optional<Eigen::Vector2d> px =
      swarm::ProjectToPixel(Eigen::Vector3d(v.position_m.x(), v.position_m.y(), 0.0), s.intrinsics, s.true_pose);
  if (!px) return std::nullopt;
  return Eigen::Vector2d(swarm::InputToCanonical(px->x(), scale), swarm::InputToCanonical(px->y(), scale));
}

struct Labelled {
  std::vector<float> x;  // rows of the model's forest_inputs() (stage 2) or kWindowFeatures (stage 1)
  std::vector<float> blob;  // stage 1 with blob features: kBlobFeatures per row
  std::vector<int> y;
  std::vector<float> target;  // stage 1: regression target (1 centred, kShiftedTarget shifted, -1)
  int rows() const { return static_cast<int>(y.size()); }
};

// The second stage: cv::ml::RTrees on rows of `inputs` features, seeded; with balance_classes the
// classes weighted equally (priors inverse to their counts: ten negatives or more to a positive).
Result<cv::Ptr<cv::ml::RTrees>> TrainForest(Labelled& d, int inputs, const TrainingOptions& o) {
  int pos = 0;
  for (int y : d.y) pos += y;
  cv::Mat x(d.rows(), inputs, CV_32F, d.x.data());
  cv::Mat y(d.rows(), 1, CV_32S, d.y.data());
  cv::Ptr<cv::ml::RTrees> forest = cv::ml::RTrees::create();
  forest->setMaxDepth(o.forest_depth);
  forest->setMinSampleCount(4);
  forest->setActiveVarCount(0);  // sqrt(features)
  forest->setCalculateVarImportance(false);
  if (o.balance_classes) {
    forest->setPriors(cv::Mat(cv::Matx12f(1.0f, static_cast<float>(d.rows() - pos) / static_cast<float>(std::max(1, pos)))));
  }
  forest->setTermCriteria(cv::TermCriteria(cv::TermCriteria::MAX_ITER, o.forest_trees, 0));
  cv::theRNG().state = 0x5EED;  // the forest's bootstrap samples and variable subsets
  if (!forest->train(cv::ml::TrainData::create(x, cv::ml::ROW_SAMPLE, y))) {
    return Error(ErrorCode::kInternal, "train-detector: RTrees training failed");
  }
  return forest;
}

cv::Mat BgrOf(const Scene& s) {
  return cv::Mat(s.image.height_px, s.image.width_px, CV_8UC3, const_cast<std::uint8_t*>(s.image.bgr.data()));
}

// Nearest person (any visibility > 0) to a canonical point, in metres, and whether it must be detected.
std::pair<double, bool> NearestPerson(const Scene& s, double scale, const Eigen::Vector2d& canonical) {
  double best = 1e9;
  bool must = false;
  for (const SceneVictim& v : s.victims) {
    if (v.visible_fraction <= 0) continue;
    const std::optional<Eigen::Vector2d> c = CanonicalOf(v, s, scale);
    if (!c) continue;
    const double d = (*c - canonical).norm() / swarm::kCanonicalPxPerM;
    if (d < best) {
      best = d;
      must = v.visible_fraction >= kMustDetectFraction;
    }
  }
  return {best, must};
}

// Clutter painted on a rendered frame, away from every person: tarps and sheets (rotated
// rectangles 0.5-4 m, any colour, orange and red often), round things (cones, rocks, backpacks seen
// from above: 0.2-0.8 m) and specks. What the renderer cannot draw yet, so the forest also learns
// that colour alone is not a person.
void PaintClutter(Scene& s, double ppm, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  cv::Mat img(s.image.height_px, s.image.width_px, CV_8UC3, s.image.bgr.data());
  const int count = static_cast<int>(u(rng) * 4);
  for (int k = 0; k < count; ++k) {
    const double size_m = u(rng) < 0.5 ? 0.5 + 3.5 * u(rng) : 0.2 + 0.6 * u(rng);
    const cv::Point2d c(u(rng) * img.cols, u(rng) * img.rows);
    bool clear = true;
    for (const SceneVictim& v : s.victims) {
      const std::optional<Eigen::Vector2d> px =
          swarm::ProjectToPixel(Eigen::Vector3d(v.position_m.x(), v.position_m.y(), 0.0), s.intrinsics, s.true_pose);
      if (px && std::hypot(px->x() - c.x, px->y() - c.y) < (1.5 + size_m) * ppm) clear = false;
    }
    if (!clear) continue;
    cv::Scalar colour(255 * u(rng), 255 * u(rng), 255 * u(rng));
    const double pick = u(rng);
    if (pick < 0.3) colour = cv::Scalar(20 * u(rng), 80 + 80 * u(rng), 200 + 55 * u(rng));  // orange
    else if (pick < 0.45) colour = cv::Scalar(30 * u(rng), 30 * u(rng), 150 + 105 * u(rng));  // red
    const double w = size_m * ppm, h = size_m * (0.4 + 0.6 * u(rng)) * ppm;
    if (size_m > 0.8 || u(rng) < 0.5) {
      const cv::RotatedRect r(c, cv::Size2f(static_cast<float>(w), static_cast<float>(h)), static_cast<float>(180 * u(rng)));
      cv::Point2f p[4];
      r.points(p);
      std::vector<cv::Point> poly(p, p + 4);
      cv::fillConvexPoly(img, poly, colour, cv::LINE_AA);
    } else {
      cv::circle(img, c, std::max(1, static_cast<int>(w / 2)), colour, cv::FILLED, cv::LINE_AA);
    }
  }
}

std::size_t NearestIndex(const Scene& s, double scale, const Eigen::Vector2d& canonical) {
  std::size_t best = s.victims.size();
  double best_d = 1e18;
  for (std::size_t i = 0; i < s.victims.size(); ++i) {
    const std::optional<Eigen::Vector2d> c = CanonicalOf(s.victims[i], s, scale);
    if (!c) continue;
    const double d = (*c - canonical).norm();
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

// The scene sets of `seeds`, each made by set_params(seed, scenes); half of the frames get clutter
// unless `clutter` is false.
template <typename SetParams>
Result<std::vector<Scene>> RenderSets(const std::vector<std::uint64_t>& seeds, int scenes, SetParams set_params,
                                      bool clutter = true) {
  std::vector<Scene> all;
  std::mt19937_64 rng(0xC1A77E5);
  for (std::uint64_t seed : seeds) {
    Result<std::vector<Scene>> s = perception_scenes::RenderScenes(set_params(seed, scenes));
    if (!s) return s.error().Context("rendering training scene set " + std::to_string(seed));
    for (Scene& x : *s) {
      if (clutter && std::uniform_real_distribution<double>(0, 1)(rng) < 0.5) PaintClutter(x, PixelsPerMetre(x), rng);
      all.push_back(std::move(x));
    }
  }
  return all;
}

// Each feature's mean and standard deviation (at least 1e-6) over the rows of x.
struct Standardisation {
  cv::Mat mean_row, std_row;  // 1 x features, CV_64F
};

Standardisation Standardise(const cv::Mat& x, int f) {
  Standardisation st{cv::Mat(1, f, CV_64F), cv::Mat(1, f, CV_64F)};
  cv::Mat mean, stddev;
  for (int j = 0; j < f; ++j) {
    cv::meanStdDev(x.col(j), mean, stddev);
    st.mean_row.at<double>(j) = mean.at<double>(0);
    st.std_row.at<double>(j) = std::max(stddev.at<double>(0), 1e-6);
  }
  return st;
}

// The ridge solution w (features + bias) of the class-weighted standardised design.
cv::Mat SolveRidge(const Labelled& d, const cv::Mat& x, const Standardisation& st, double lambda) {
  const int n = d.rows(), f = swarm::kWindowFeatures;
  int pos = 0;
  for (int y : d.y) pos += y;
  const double wp = 0.5 / std::max(1, pos), wn = 0.5 / std::max(1, n - pos);
  cv::Mat z(n, f + 1, CV_32F), t(n, 1, CV_32F);
  for (int i = 0; i < n; ++i) {
    const float* xi = x.ptr<float>(i);
    float* zi = z.ptr<float>(i);
    const double sw = std::sqrt(d.y[static_cast<std::size_t>(i)] ? wp : wn);
    for (int j = 0; j < f; ++j) {
      zi[j] = static_cast<float>(sw * (xi[j] - st.mean_row.at<double>(j)) / st.std_row.at<double>(j));
    }
    zi[f] = static_cast<float>(sw);
    t.at<float>(i) = static_cast<float>(sw * d.target[static_cast<std::size_t>(i)]);
  }
  cv::Mat ztz, ztt;
  cv::mulTransposed(z, ztz, true);
  ztt = z.t() * t;
  cv::Mat a, b;
  ztz.convertTo(a, CV_64F);
  ztt.convertTo(b, CV_64F);
  for (int j = 0; j < f; ++j) a.at<double>(j, j) += lambda;  // the bias is not shrunk
  cv::Mat w;
  cv::solve(a, b, w, cv::DECOMP_CHOLESKY);
  return w;
}

// Ridge-regression discriminant on standardised features, targets +-1 with the classes weighted
// equally; returns weights and bias over raw features.
std::pair<std::vector<double>, double> FitLinear(const Labelled& d, double lambda) {
  const int n = d.rows(), f = swarm::kWindowFeatures;
  cv::Mat x(n, f, CV_32F, const_cast<float*>(d.x.data()));
  const Standardisation st = Standardise(x, f);
  const cv::Mat w = SolveRidge(d, x, st, lambda);
  std::vector<double> weights(static_cast<std::size_t>(f));
  double bias = w.at<double>(f);
  for (int j = 0; j < f; ++j) {
    weights[static_cast<std::size_t>(j)] = w.at<double>(j) / st.std_row.at<double>(j);
    bias -= w.at<double>(j) * st.mean_row.at<double>(j) / st.std_row.at<double>(j);
  }
  return {weights, bias};
}

// Platt's fit: scores v, labels y, his smoothed targets (N+ + 1) / (N+ + 2) and 1 / (N- + 2).
struct PlattProblem {
  const std::vector<double>& v;
  const std::vector<int>& y;
  double tp, tn;

  // Numerically stable log loss of targets t against p = 1 / (1 + exp(f)), f = a v + b.
  double Loss(double a, double b) const {
    double l = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const double f = a * v[i] + b, t = y[i] ? tp : tn;
      l += f >= 0 ? t * f + std::log1p(std::exp(-f)) : (t - 1) * f + std::log1p(std::exp(f));
    }
    return l;
  }

  // The Newton direction at (a, b) and the gradient along it; nothing when converged or singular.
  std::optional<std::array<double, 3>> Direction(double a, double b) const {
    double ga = 0, gb = 0, haa = 1e-12, hab = 0, hbb = 1e-12;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const double f = a * v[i] + b;
      const double p = f >= 0 ? std::exp(-f) / (1 + std::exp(-f)) : 1 / (1 + std::exp(f));
      const double t = y[i] ? tp : tn;
      const double g = t - p, h = p * (1 - p);
      ga += g * v[i];
      gb += g;
      haa += h * v[i] * v[i];
      hab += h * v[i];
      hbb += h;
    }
    if (std::abs(ga) < 1e-5 && std::abs(gb) < 1e-5) return std::nullopt;
    const double det = haa * hbb - hab * hab;
    if (std::abs(det) < 1e-18) return std::nullopt;
    const double da = -(hbb * ga - hab * gb) / det, db = -(haa * gb - hab * ga) / det;
    return std::array<double, 3>{da, db, ga * da + gb * db};
  }
};

// Platt's sigmoid p = 1 / (1 + exp(a v + b)) by Newton's method on the log loss, with his
// smoothed targets (N+ + 1) / (N+ + 2) and 1 / (N- + 2).
std::pair<double, double> FitPlatt(const std::vector<double>& v, const std::vector<int>& y) {
  double np = 0, nn = 0;
  for (int l : y) (l ? np : nn) += 1;
  const PlattProblem problem{v, y, (np + 1) / (np + 2), 1 / (nn + 2)};
  // Newton's method with backtracking (Lin, Lin and Weng 2007, "A note on Platt's probabilistic
  // outputs for support vector machines").
  double a = 0, b = std::log((nn + 1) / (np + 1));
  double fval = problem.Loss(a, b);
  for (int it = 0; it < 100; ++it) {
    const std::optional<std::array<double, 3>> dir = problem.Direction(a, b);
    if (!dir) break;
    const auto [da, db, gd] = *dir;
    double step = 1;
    while (step >= 1e-10) {
      const double na = a + step * da, nb = b + step * db, nf = problem.Loss(na, nb);
      if (nf < fval + 1e-4 * step * gd) {
        a = na;
        b = nb;
        fval = nf;
        break;
      }
      step /= 2;
    }
    if (step < 1e-10) break;
  }
  return {a, b};
}

}  // namespace

std::string RecipeText(const TrainingOptions& o) {
  std::ostringstream r;
  r << "swarmbox-train-detector --training-sets " << o.training_seeds.size() << " --scenes-per-set " << o.scenes_per_set
    << " --trees " << o.forest_trees << " --max-negatives " << o.max_negatives << " --stage1-percentile "
    << o.stage1_percentile << " --hard-negative-rounds " << o.hard_negative_rounds;
  if (o.balance_classes) r << " --balance-classes";
  if (o.blob_features) r << " --blob-features";
  if (o.negatives_sets > 0) r << " --negatives-sets " << o.negatives_sets;
  if (o.world_sets > 0) r << " --world-sets " << o.world_sets;
  if (o.world_distractors != 25) r << " --world-distractors " << o.world_distractors;
  if (o.stage1_rounds > 0) r << " --stage1-rounds " << o.stage1_rounds;
  if (o.calibration_altitude_m > 0) r << " --calibration-altitude " << o.calibration_altitude_m;
  if (o.close_calibration_altitude_m > 0)
    r << " --close-calibration-altitude " << o.close_calibration_altitude_m;
  if (o.max_candidates != swarm::VictimDetectorParams{}.max_candidates) r << " --max-candidates " << o.max_candidates;
  if (o.operating_precision > 0) r << " --operating-precision " << o.operating_precision;
  if (o.calibration_seeds != SeedSets(kCalibrationSeedBase, 2)) r << " --calibration-sets " << o.calibration_seeds.size();
  if (o.clean_calibration) r << " --clean-calibration";
  if (o.view_min_altitude_m > 0)
    r << " --view-altitudes " << o.view_min_altitude_m << "," << o.view_max_altitude_m;
  if (o.cnn_patch_px != swarm::kCnnPatchPx) r << " --cnn-patch-px " << o.cnn_patch_px;
  if (o.cnn_symmetries > 1) r << " --cnn-symmetries " << o.cnn_symmetries;
  if (!o.cnn_script.empty()) {
    r << " --cnn train_cnn.py --cnn-epochs " << o.cnn_epochs << " --cnn-seed " << o.cnn_seed
      << " --cnn-widths " << o.cnn_widths << " --cnn-negatives " << o.cnn_negatives_per_epoch
      << " --cnn-hard-fraction " << o.cnn_hard_fraction;
  }
  return r.str();
}

TrainingOptions DefaultTrainingOptions() {
  TrainingOptions o;
  o.training_seeds = SeedSets(kTrainingSeedBase, 8);
  o.calibration_seeds = SeedSets(kCalibrationSeedBase, 2);
  return o;
}

std::vector<std::uint64_t> SeedSets(std::uint64_t base, int sets) {
  std::vector<std::uint64_t> seeds;
  for (int k = 1; k <= sets; ++k) seeds.push_back(base + static_cast<std::uint64_t>(k));
  return seeds;
}

perception_scenes::SceneSetParams TrainingSceneSet(std::uint64_t seed, int scenes) {
  return {.seed = seed,
          .scenes = scenes,
          .scenes_per_world = 20,
          .min_altitude_m = 8.0,
          .max_altitude_m = 65.0,
          .min_noise_std = 2.0,
          .max_noise_std = 12.0,
          .near_victim_fraction = 0.8,
          .near_victim_offset = 1.0,
          .occluded_fraction = 0.3,
          .distractors = 2,
          .varied_look = seed % 4 != 0};
}

perception_scenes::SceneSetParams NegativesSceneSet(std::uint64_t seed, int scenes) {
  constexpr int kConesPerPerson = 4;
  perception_scenes::SceneSetParams p = TrainingSceneSet(seed, scenes);
  p.distractors = kConesPerPerson;
  p.varied_look = true;
  p.distractor_mix = perception_scenes::DistractorMix::kConesRubble;
  return p;
}

perception_scenes::SceneSetParams WorldSceneSet(std::uint64_t seed, int scenes, int distractors) {
  perception_scenes::SceneSetParams p = TrainingSceneSet(seed, scenes);
  p.min_altitude_m = 15.0;
  p.max_altitude_m = 45.0;
  p.generated = perception_scenes::SarRubbleSpec();
  p.generated->distractors = distractors;
  return p;
}

perception_scenes::SceneSetParams CalibrationSceneSet(std::uint64_t seed, int scenes, double calibration_altitude_m) {
  perception_scenes::SceneSetParams p = TrainingSceneSet(seed, scenes);
  if (calibration_altitude_m > 0) {
    p.min_altitude_m = calibration_altitude_m - kCalibrationAltitudeBandM;
    p.max_altitude_m = calibration_altitude_m + kCalibrationAltitudeBandM;
  }
  return p;
}

namespace {

// The seeds of the cones-and-rubble sets.
std::vector<std::uint64_t> NegativesSeeds(const TrainingOptions& o) {
  return SeedSets(kNegativesSeedBase, o.negatives_sets);
}
// The seeds of the generated rubble-field sets.
std::vector<std::uint64_t> WorldSeeds(const TrainingOptions& o) { return SeedSets(kWorldsSeedBase, o.world_sets); }

Result<std::vector<Scene>> RenderCalibrationSets(const TrainingOptions& o) {
  return RenderSets(
      o.calibration_seeds, o.scenes_per_set,
      [&o](std::uint64_t seed, int scenes) { return CalibrationSceneSet(seed, scenes, o.calibration_altitude_m); },
      !o.clean_calibration);
}

}  // namespace

namespace {

// A calibration detection: its scene, the nearest person, the forest's votes, and whether it is
// a person (1) or clearly none (0).
struct CalibrationDetection {
  std::size_t scene;
  std::size_t person;
  double votes;
  int label;
};

// The detector at no threshold on the calibration scenes: each detection within 1 m of a
// must-detect person is a positive, one kNegativeRadiusM from every person a negative.
std::vector<CalibrationDetection> LabelledDetections(const std::vector<Scene>& cal, swarm::VictimDetector& det,
                                                     TrainingReport* report) {
  std::vector<CalibrationDetection> dets;
  std::vector<swarm::ImageBlob> blobs;
  for (std::size_t i = 0; i < cal.size(); ++i) {
    const Scene& s = cal[i];
    const double ppm = PixelsPerMetre(s), scale = swarm::kCanonicalPxPerM / ppm;
    det.Detect(BgrOf(s), s.intrinsics, s.true_pose, 0.0, &blobs);
    for (const swarm::ImageBlob& b : blobs) {
      const Eigen::Vector2d c(swarm::InputToCanonical(b.centroid_px.x(), scale),
                              swarm::InputToCanonical(b.centroid_px.y(), scale));
      const auto [dist, must] = NearestPerson(s, scale, c);
      int label = -1;
      if (dist <= 1.0 && must) label = 1;
      if (dist >= kNegativeRadiusM) label = 0;
      if (label < 0) continue;
      dets.push_back({i, NearestIndex(s, scale, c), b.votes, label});
    }
    for (const SceneVictim& v : s.victims) report->calibration_persons += v.visible_fraction >= kMustDetectFraction ? 1 : 0;
  }
  return dets;
}

// First-stage recall on the calibration scenes: must-detect people with a candidate within
// kPositiveRadiusM.
void MeasureStage1Recall(const std::vector<Scene>& cal, swarm::VictimDetector& det, int max_candidates,
                         double threshold, TrainingReport* report) {
  int hit = 0, must_total = 0;
  for (const Scene& s : cal) {
    const double ppm = PixelsPerMetre(s), scale = swarm::kCanonicalPxPerM / ppm;
    const auto& cands = det.Candidates(BgrOf(s), ppm, max_candidates, threshold);
    for (const SceneVictim& v : s.victims) {
      if (v.visible_fraction < kMustDetectFraction) continue;
      const std::optional<Eigen::Vector2d> c = CanonicalOf(v, s, scale);
      if (!c) continue;
      ++must_total;
      for (const auto& k : cands) {
        const Eigen::Vector2d centre(swarm::WindowCentreCanonical(0) + swarm::kShrink * k.sub_col,
                                     swarm::WindowCentreCanonical(0) + swarm::kShrink * k.sub_row);
        if ((centre - *c).norm() / swarm::kCanonicalPxPerM <= kPositiveRadiusM) {
          ++hit;
          break;
        }
      }
    }
  }
  report->stage1_calibration_recall = must_total ? static_cast<double>(hit) / must_total : 1.0;
  std::fprintf(stderr, "train-detector: first-stage recall on the calibration scenes %.4f (%d people)\n",
               report->stage1_calibration_recall, must_total);
}

// The calibrated model's figures at probability 0.5: people found (once each), false positives,
// precision and recall.
void CountCalibrationFigures(const swarm::VictimDetectorModel& model, const std::vector<CalibrationDetection>& dets,
                             TrainingReport* report) {
  report->calibration_detections = static_cast<int>(dets.size());
  std::set<std::pair<std::size_t, std::size_t>> found;  // (scene, person) detected at 0.5
  for (const CalibrationDetection& d : dets) {
    if (model.Probability(d.votes) < 0.5) continue;
    if (d.label) {
      found.insert({d.scene, d.person});
    } else {
      ++report->calibration_fp;
    }
  }
  report->calibration_tp = static_cast<int>(found.size());
  const int called = report->calibration_tp + report->calibration_fp;
  report->precision = called ? static_cast<double>(report->calibration_tp) / called : 1.0;
  report->recall = report->calibration_persons ? static_cast<double>(report->calibration_tp) / report->calibration_persons : 1.0;
}

// The lowest vote fraction at which the calibration detections reach `precision` (people found once
// each, as CountCalibrationFigures counts them): the operating point that keeps the most people;
// nullopt when no vote fraction reaches it.
std::optional<double> VotesAtPrecision(const std::vector<CalibrationDetection>& dets, double precision) {
  std::vector<double> thresholds;
  for (const CalibrationDetection& d : dets) thresholds.push_back(d.votes);
  std::sort(thresholds.begin(), thresholds.end());
  thresholds.erase(std::unique(thresholds.begin(), thresholds.end()), thresholds.end());
  for (double v : thresholds) {
    std::set<std::pair<std::size_t, std::size_t>> found;
    int fp = 0;
    for (const CalibrationDetection& d : dets) {
      if (d.votes < v) continue;
      if (d.label) {
        found.insert({d.scene, d.person});
      } else {
        ++fp;
      }
    }
    const int called = static_cast<int>(found.size()) + fp;
    if (called > 0 && static_cast<double>(found.size()) / called >= precision) return v;
  }
  return std::nullopt;
}

}  // namespace

// Calibration on scenes the forest has not seen: the Platt sigmoid on the labelled detections'
// votes (moved to the operating point when o.operating_precision is set), and the figures.
Status Calibrate(const std::vector<Scene>& calibration, const TrainingOptions& o, swarm::VictimDetectorModel* model_out,
                 TrainingReport* report) {
  const int max_candidates = o.max_candidates;
  swarm::VictimDetectorModel& model = *model_out;
  auto shared = std::make_shared<swarm::VictimDetectorModel>(model);
  swarm::VictimDetectorParams raw;
  raw.max_candidates = max_candidates;
  raw.min_confidence = 0.0;
  raw.partial_confidence_cap = 1.0;
  swarm::VictimDetector det(shared, raw);
  const std::vector<CalibrationDetection> dets = LabelledDetections(calibration, det, report);
  MeasureStage1Recall(calibration, det, raw.max_candidates, model.stage1_threshold, report);
  std::vector<double> votes;
  std::vector<int> labels;
  for (const CalibrationDetection& d : dets) {
    votes.push_back(d.votes);
    labels.push_back(d.label);
  }
  const auto [a, b] = FitPlatt(votes, labels);
  model.platt_a = a;
  model.platt_b = b;
  if (o.operating_precision > 0) {
    const std::optional<double> v = VotesAtPrecision(dets, o.operating_precision);
    if (!v || a >= 0) {
      return Error(ErrorCode::kInvalidArgument, "train-detector: the calibration detections reach precision " +
                                                    std::to_string(o.operating_precision) + " at no vote fraction");
    }
    // Probability(votes) = 1 / (1 + exp(a votes + b)) is 0.5 where a votes + b = 0.
    model.platt_b = -a * *v;
    std::fprintf(stderr, "train-detector: operating point at votes %.4f (Platt's 0.5 at %.4f)\n", *v, -b / a);
  }
  CountCalibrationFigures(model, dets, report);
  return Ok{};
}

namespace {

// `flag` (" --name ") and its value out of the recipe, when it names them.
void EraseFlag(const std::string& flag, std::string* recipe) {
  if (const std::size_t at = recipe->find(flag); at != std::string::npos) {
    const std::size_t end = recipe->find(' ', at + flag.size());
    recipe->erase(at, end == std::string::npos ? std::string::npos : end - at);
  }
}

// The recalibration's options that the model's recipe does not name yet, appended to it (the
// calibration's altitude band, the cap, new calibration sets, clean frames, the operating point);
// the close sigmoid's and the symmetries' replace what it names.
void AppendRecalibrationRecipe(const TrainingOptions& o, bool new_seeds, std::string* recipe) {
  auto add = [recipe](bool wanted, const std::string& flag, const std::string& value) {
    if (wanted && recipe->find(flag) == std::string::npos) *recipe += " " + flag + (value.empty() ? "" : " " + value);
  };
  std::ostringstream altitude, precision;
  altitude << o.calibration_altitude_m;
  precision << o.operating_precision;
  add(o.calibration_altitude_m > 0, "--calibration-altitude", altitude.str());
  EraseFlag(" --close-calibration-altitude ", recipe);  // refitted below, or dropped (CalibrateClose)
  std::ostringstream close_altitude;
  close_altitude << o.close_calibration_altitude_m;
  add(o.close_calibration_altitude_m > 0, "--close-calibration-altitude", close_altitude.str());
  add(o.max_candidates != swarm::VictimDetectorParams{}.max_candidates, "--max-candidates",
      std::to_string(o.max_candidates));
  add(new_seeds, "--calibration-sets", std::to_string(o.calibration_seeds.size()));
  add(o.clean_calibration, "--clean-calibration", "");
  add(o.operating_precision > 0, "--operating-precision", precision.str());
  add(!o.replace_cnn.empty(), "--replace-cnn", o.replace_cnn.substr(o.replace_cnn.find_last_of('/') + 1));
  if (!o.close_cnn.empty()) {  // a new close CNN replaces one the recipe named
    EraseFlag(" --close-cnn ", recipe);
    EraseFlag(" --close-cnn-patch-px ", recipe);
    *recipe += " --close-cnn " + o.close_cnn.substr(o.close_cnn.find_last_of('/') + 1) +
               " --close-cnn-patch-px " + std::to_string(o.close_cnn_patch_px);
  }
  if (o.cnn_symmetries > 0) {  // the new count replaces one the recipe named
    EraseFlag(" --cnn-symmetries ", recipe);
    *recipe += " --cnn-symmetries " + std::to_string(o.cnn_symmetries);
  }
}

}  // namespace

namespace {

// The ONNX at `path` into *onnx (the model's cnn_onnx or close_cnn_onnx), checked to load in cv::dnn.
Status ReadCnn(const std::string& path, std::vector<std::uint8_t>* onnx) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  onnx->resize(in ? static_cast<std::size_t>(in.tellg()) : 0);
  in.seekg(0);
  in.read(reinterpret_cast<char*>(onnx->data()), static_cast<std::streamsize>(onnx->size()));
  if (!in) onnx->clear();
  if (onnx->empty()) {
    return Error(ErrorCode::kIo, "train-detector: no ONNX there (missing or empty)", path);
  }
  try {
    if (cv::dnn::readNetFromONNX(path).empty()) throw cv::Exception();
  } catch (const cv::Exception& e) {
    return Error(ErrorCode::kInvalidArgument,
                 std::string("train-detector: cv::dnn cannot read the CNN: ") + e.what(), path);
  }
  return Ok{};
}

}  // namespace

namespace {

// No close sigmoid, or one whose calibration band lies wholly under the first's.
bool CloseCalibrationOk(const TrainingOptions& o) {
  return o.close_calibration_altitude_m == 0 ||
         (o.close_calibration_altitude_m > kCalibrationAltitudeBandM &&
          o.calibration_altitude_m >= o.close_calibration_altitude_m + 2 * kCalibrationAltitudeBandM);
}

Status CheckTrainingOptions(const TrainingOptions& o);  // below, with the training's other checks

double MedianScale(const std::vector<Scene>& scenes) {
  std::vector<double> scales;
  for (const Scene& s : scenes) scales.push_back(PixelsPerMetre(s));
  std::nth_element(scales.begin(), scales.begin() + static_cast<std::ptrdiff_t>(scales.size() / 2),
                   scales.end());
  return scales[scales.size() / 2];
}

// The close sigmoid (o.close_calibration_altitude_m > 0, CloseCalibrationOk checked by
// CheckTrainingOptions; TrainingOptions): fitted as Calibrate fits the first, on the calibration
// seeds rendered at the close altitude. Without the option a
// recalibrated model has none (one fitted to its scores before would not be refitted).
Status CalibrateClose(const std::vector<Scene>& search_calibration, const TrainingOptions& o,
                      swarm::VictimDetectorModel* model) {
  model->close_px_per_m = 0;
  if (o.close_calibration_altitude_m <= 0) {
    model->close_cnn_onnx.clear();  // a close CNN goes with the close sigmoid
    model->close_cnn_patch_px = 0;
    return Ok{};
  }
  TrainingOptions at_close = o;
  at_close.calibration_altitude_m = o.close_calibration_altitude_m;
  at_close.operating_precision = 0;
  Result<std::vector<Scene>> close = RenderCalibrationSets(at_close);
  if (!close) return close.error();
  // With a close CNN the sigmoid is fitted to its logits: the model as close frames see it.
  swarm::VictimDetectorModel fitted = model->has_close_cnn() ? model->CloseView() : *model;
  TrainingReport figures;
  if (Status st = Calibrate(*close, at_close, &fitted, &figures); !st) return st.error();
  model->close_platt_a = fitted.platt_a;
  model->close_platt_b = fitted.platt_b;
  model->close_px_per_m = std::sqrt(MedianScale(search_calibration) * MedianScale(*close));
  std::fprintf(stderr,
               "train-detector: close sigmoid%s from %zu scenes at %.0f m (a %.4f, b %.4f) "
               "for frames of >= %.2f px/m: precision %.4f recall %.4f at 0.5 there\n",
               model->has_close_cnn() ? " (of the close CNN)" : "", close->size(),
               o.close_calibration_altitude_m, fitted.platt_a, fitted.platt_b, model->close_px_per_m,
               figures.precision, figures.recall);
  return Ok{};
}

}  // namespace

namespace {

// A recalibration's changes to the model's networks: another CNN (--replace-cnn), a close-look CNN
// (--close-cnn), the symmetries each patch is scored in (--cnn-symmetries).
Status ApplyCnnOptions(const TrainingOptions& o, const std::string& model_path,
                       swarm::VictimDetectorModel* model) {
  if (!model->has_cnn() && (!o.replace_cnn.empty() || !o.close_cnn.empty() || o.cnn_symmetries > 0)) {
    return Error(ErrorCode::kInvalidArgument,
                 "recalibrate: --replace-cnn, --close-cnn and --cnn-symmetries need a CNN model", model_path);
  }
  if (!o.replace_cnn.empty()) SWARMBOX_TRY(ReadCnn(o.replace_cnn, &model->cnn_onnx));
  if (!o.close_cnn.empty()) {
    if (o.close_calibration_altitude_m <= 0) {
      return Error(ErrorCode::kInvalidArgument, "recalibrate: --close-cnn needs --close-calibration-altitude",
                   model_path);
    }
    SWARMBOX_TRY(ReadCnn(o.close_cnn, &model->close_cnn_onnx));
    model->close_cnn_patch_px = o.close_cnn_patch_px;
  }
  if (o.cnn_symmetries > 0) model->cnn_symmetries = o.cnn_symmetries;
  return Ok{};
}

}  // namespace

Result<swarm::VictimDetectorModel> Recalibrate(const TrainingOptions& o, const std::string& model_path,
                                               TrainingReport* report) {
  SWARMBOX_TRY(CheckTrainingOptions(o));  // before the model is read or a frame rendered
  Result<std::shared_ptr<const swarm::VictimDetectorModel>> loaded = swarm::LoadDetectorModel(model_path);
  if (!loaded) return loaded.error();
  swarm::VictimDetectorModel model = **loaded;
  // Other calibration seeds (--calibration-sets) replace the model's; they must not be ones it was
  // trained on.
  for (std::uint64_t s : o.calibration_seeds) {
    if (std::find(model.training_seeds.begin(), model.training_seeds.end(), s) != model.training_seeds.end()) {
      return Error(ErrorCode::kInvalidArgument, "recalibrate: calibration seed " + std::to_string(s) +
                                                    " is one the model was trained on", model_path);
    }
  }
  SWARMBOX_TRY(ApplyCnnOptions(o, model_path, &model));
  const bool new_seeds = model.calibration_seeds != o.calibration_seeds;
  model.calibration_seeds = o.calibration_seeds;
  Result<std::vector<Scene>> cal = RenderCalibrationSets(o);
  if (!cal) return cal.error();
  report->calibration_scenes = static_cast<int>(cal->size());
  if (Status st = Calibrate(*cal, o, &model, report); !st) return st.error();
  SWARMBOX_TRY(CalibrateClose(*cal, o, &model));
  AppendRecalibrationRecipe(o, new_seeds, &model.recipe);
  return model;
}

namespace {

// "A,B,C" with three positive integers (train_cnn.py --widths).
bool ThreeWidths(const std::string& text) {
  std::istringstream in(text);
  int count = 0;
  for (std::string part; std::getline(in, part, ',');) {
    const bool digits = !part.empty() && part.size() <= 4 && part.find_first_not_of("0123456789") == std::string::npos;
    if (!digits || std::stoi(part) < 1) return false;
    ++count;
  }
  return count == 3;
}

Status CheckTrainingOptions(const TrainingOptions& o) {
  if (!(o.stage1_percentile >= 0 && o.stage1_percentile < 100) || o.forest_trees < 1 || o.max_negatives < 1 ||
      o.hard_negative_rounds < 0 || o.max_candidates < 1 ||
      !(o.operating_precision >= 0 && o.operating_precision < 1) || o.negatives_sets < 0 ||
      o.world_sets < 0 || o.world_distractors < 0 || o.stage1_rounds < 0 ||
      (o.stage1_rounds > 0 && o.blob_features) || o.calibration_altitude_m < 0 || o.cnn_epochs < 1 ||
      (!o.cnn_script.empty() && o.cnn_onnx_out.empty()) || !swarm::ValidCnnPatchPx(o.cnn_patch_px) ||
      !swarm::ValidCnnPatchPx(o.close_cnn_patch_px) ||
      (o.cnn_symmetries != 0 && !swarm::ValidCnnSymmetries(o.cnn_symmetries)) || !CloseCalibrationOk(o) ||
      ((o.view_min_altitude_m != 0 || o.view_max_altitude_m != 0) &&
       !(o.view_min_altitude_m >= 2 && o.view_max_altitude_m > o.view_min_altitude_m))) {
    return Error(
        ErrorCode::kInvalidArgument,
        "train-detector: stage1_percentile must be in [0, 100), trees and max_negatives >= 1, "
        "max_candidates >= 1, operating_precision in [0, 1), hard_negative_rounds, negatives_sets, "
        "world_sets, world_distractors, stage1_rounds (not with blob features) and "
        "calibration_altitude_m >= 0, cnn_epochs >= 1, a CNN needs its ONNX path, --cnn-symmetries is 1, 4 "
        "or 8, --close-calibration-altitude is above 3 m and at least 6 m under --calibration-altitude, "
        "--cnn-patch-px and --close-cnn-patch-px are multiples of 8 in [16, 128], "
        "--view-altitudes LO,HI has 2 <= LO < HI");
  }
  if (!o.cnn_script.empty() && (!ThreeWidths(o.cnn_widths) || o.cnn_negatives_per_epoch < 1 ||
                                !(o.cnn_hard_fraction >= 0 && o.cnn_hard_fraction < 1))) {
    return Error(ErrorCode::kInvalidArgument, "train-detector: --cnn-widths takes three positive channel counts "
                                              "(e.g. 24,48,96), --cnn-negatives a count >= 1 and "
                                              "--cnn-hard-fraction a share in [0, 1)");
  }
  const std::vector<std::uint64_t> negatives_seeds = NegativesSeeds(o);
  const std::vector<std::uint64_t> world_seeds = WorldSeeds(o);
  for (const auto* list : {&o.training_seeds, &o.calibration_seeds, &negatives_seeds, &world_seeds}) {
    for (std::uint64_t s : *list) {
      for (std::uint64_t e : perception_scenes::kEvaluationSeeds) {
        if (s == e) return Error(ErrorCode::kInvalidArgument, "training seed " + std::to_string(s) + " is an evaluation seed");
      }
    }
  }
  return Ok{};
}

// What the training's stages share: the options, the report, the start time (for the progress
// lines), the seeded generator (stage 1's random negatives, then the negatives' sample) and the
// model being trained.
struct Training {
  const TrainingOptions& o;
  TrainingReport* report;
  std::chrono::steady_clock::time_point t0;
  std::mt19937_64 rng{0x7EA1};
  swarm::VictimDetectorModel model = {};
};

// Windows of one scene into stage 1's samples, with their blob features when `blob` is set (the
// second stage's positives are taken from these rows too).
struct Stage1Sampler {
  const swarm::ChannelMaps& maps;
  swarm::BlobFeatureExtractor* blob;  // null: a model without blob features
  double scale;                       // canonical pixels per frame pixel
  int rows, cols;                     // window positions
  Labelled* s1;
  std::vector<float> window = std::vector<float>(swarm::kWindowFeatures);
  std::vector<float> shape = std::vector<float>(swarm::kBlobFeatures);

  bool Add(int r, int c, int label, float target) {
    if (r < 0 || c < 0 || r >= rows || c >= cols) return false;
    swarm::WindowFeatures(maps, r, c, window.data());
    s1->x.insert(s1->x.end(), window.begin(), window.end());
    s1->y.push_back(label);
    s1->target.push_back(target);
    if (blob != nullptr) {
      blob->Extract({swarm::CanonicalToInput(swarm::WindowCentreCanonical(c), scale),
                     swarm::CanonicalToInput(swarm::WindowCentreCanonical(r), scale)},
                    shape.data());
      s1->blob.insert(s1->blob.end(), shape.begin(), shape.end());
    }
    return true;
  }
};

// One scene's stage 1 samples: each must-detect person's window, centred (its row into *centred)
// and shifted by a cell each way, and random negatives away from every person.
void AddStage1Samples(const Scene& s, std::mt19937_64& rng, swarm::ChannelMaps& maps, swarm::BlobFeatureExtractor* blob,
                      Labelled* s1, std::vector<std::size_t>* centred) {
  const double ppm = PixelsPerMetre(s), scale = swarm::kCanonicalPxPerM / ppm;
  swarm::ComputeChannels(BgrOf(s), scale, &maps);
  if (blob != nullptr) blob->SetFrame(BgrOf(s), ppm);
  Stage1Sampler add{maps, blob, scale, maps.rows() - swarm::kWindowCells + 1, maps.cols() - swarm::kWindowCells + 1, s1};
  if (add.rows <= 0 || add.cols <= 0) return;
  for (const SceneVictim& v : s.victims) {
    if (v.visible_fraction < kMustDetectFraction) continue;
    const std::optional<Eigen::Vector2d> c = CanonicalOf(v, s, scale);
    if (!c) continue;
    const int r0 = static_cast<int>(std::lround(c->y() / swarm::kShrink - swarm::kWindowCells / 2.0));
    const int c0 = static_cast<int>(std::lround(c->x() / swarm::kShrink - swarm::kWindowCells / 2.0));
    if (add.Add(r0, c0, 1, 1.0f)) centred->push_back(s1->y.size() - 1);
    add.Add(r0 - 1, c0, 1, kShiftedTarget);
    add.Add(r0 + 1, c0, 1, kShiftedTarget);
    add.Add(r0, c0 - 1, 1, kShiftedTarget);
    add.Add(r0, c0 + 1, 1, kShiftedTarget);
  }
  std::uniform_int_distribution<int> rr(0, add.rows - 1), cc(0, add.cols - 1);
  for (int k = 0, tries = 0; k < kRandomNegativesPerScene && tries < 400; ++tries) {
    const int r = rr(rng), c = cc(rng);
    const Eigen::Vector2d centre(swarm::WindowCentreCanonical(c), swarm::WindowCentreCanonical(r));
    if (NearestPerson(s, scale, centre).first < kNegativeRadiusM) continue;
    add.Add(r, c, 0, -1.0f);
    ++k;
  }
}

// The ridge first stage on `s1`, its threshold at the stage1_percentile of the centred positives'
// scores.
void FitStage1(Training& t, const Labelled& s1, const std::vector<std::size_t>& centred) {
  t.report->stage1_positives = t.report->stage1_negatives = 0;
  for (int y : s1.y) (y ? t.report->stage1_positives : t.report->stage1_negatives) += 1;
  std::fprintf(stderr, "train-detector: stage 1 on %d positives, %d negatives (%.0f s)\n",
               t.report->stage1_positives, t.report->stage1_negatives, Seconds(t.t0));
  const auto [weights, bias] = FitLinear(s1, t.o.ridge_lambda);
  t.model.SetLinear(weights, bias);
  std::vector<double> centred_scores;
  for (std::size_t i : centred) centred_scores.push_back(t.model.LinearScore(&s1.x[i * swarm::kWindowFeatures]));
  std::sort(centred_scores.begin(), centred_scores.end());
  const auto at = static_cast<std::size_t>(
      std::floor(t.o.stage1_percentile / 100.0 * static_cast<double>(centred_scores.size()) + 1e-9));
  t.model.stage1_threshold =
      centred_scores.empty() ? 0.0 : centred_scores[std::min(at, centred_scores.size() - 1)];
  t.report->stage1_positive_recall = 1.0 - t.o.stage1_percentile / 100.0;
}

// The first stage's positives (centred and shifted) are second-stage positives too, with their
// first-stage score.
Labelled Stage2Positives(const swarm::VictimDetectorModel& model, const Labelled& s1) {
  Labelled s2;
  std::vector<float> g(static_cast<std::size_t>(model.forest_inputs()));
  for (std::size_t i = 0; i < s1.y.size(); ++i) {
    if (!s1.y[i]) continue;
    const float* x = &s1.x[i * swarm::kWindowFeatures];
    std::copy(x, x + swarm::kWindowFeatures, g.begin());
    g[swarm::kWindowFeatures] = static_cast<float>(model.LinearScore(x));
    if (model.blob_features > 0) {
      const float* b = &s1.blob[i * swarm::kBlobFeatures];
      std::copy(b, b + swarm::kBlobFeatures, g.begin() + swarm::kForestFeatures);
    }
    s2.x.insert(s2.x.end(), g.begin(), g.end());
    s2.y.push_back(1);
  }
  return s2;
}

// One round of stage 1's bootstrapping (Dollar et al., "Fast Feature Pyramids for Object
// Detection", PAMI 2014, section 5: the ACF detector's rounds of hard negatives): the first stage
// as fitted so far on every training scene, its kStage1HardPerScene best windows that lie
// kNegativeRadiusM or more from every person join s1's negatives. Random windows alone teach the
// ridge to tell people from average ground, not from the ground's few person-like spots (rubble
// clumps, slab corners, debris), which are what fill the candidate list.
void AddStage1HardNegatives(Training& t, const std::vector<Scene>& train, int round, Labelled* s1) {
  auto shared = std::make_shared<swarm::VictimDetectorModel>(t.model);
  swarm::VictimDetector det(shared, {});
  int added = 0;
  for (const Scene& s : train) {
    const double ppm = PixelsPerMetre(s), scale = swarm::kCanonicalPxPerM / ppm;
    const auto& cands = det.Candidates(BgrOf(s), ppm, kStage1HardPerScene, -1e30);
    const swarm::ChannelMaps& maps = det.channels();
    Stage1Sampler add{maps, nullptr, scale, maps.rows() - swarm::kWindowCells + 1,
                      maps.cols() - swarm::kWindowCells + 1, s1};
    for (const auto& c : cands) {
      const Eigen::Vector2d centre(swarm::WindowCentreCanonical(0) + swarm::kShrink * c.sub_col,
                                   swarm::WindowCentreCanonical(0) + swarm::kShrink * c.sub_row);
      if (NearestPerson(s, scale, centre).first < kNegativeRadiusM) continue;
      added += add.Add(c.row, c.col, 0, -1.0f) ? 1 : 0;
    }
  }
  std::fprintf(stderr, "train-detector: stage 1 round %d: %d hard negatives (%.0f s)\n", round + 1, added,
               Seconds(t.t0));
}

// Stage 1 from the training scenes; returns stage 2's positives.
Labelled TrainStage1(Training& t, const std::vector<Scene>& train) {
  t.model.training_seeds = t.o.training_seeds;
  for (std::uint64_t seed : NegativesSeeds(t.o)) t.model.training_seeds.push_back(seed);
  for (std::uint64_t seed : WorldSeeds(t.o)) t.model.training_seeds.push_back(seed);
  t.model.calibration_seeds = t.o.calibration_seeds;
  t.model.SetLinear(std::vector<double>(swarm::kWindowFeatures, 0.0), 0.0);
  t.model.forest = cv::ml::RTrees::create();  // replaced below; the detector needs one to exist
  t.model.blob_features = t.o.blob_features ? swarm::kBlobFeatures : 0;
  t.model.recipe = RecipeText(t.o);
  Labelled s1;
  std::vector<std::size_t> centred;  // rows of s1 that are unshifted positives
  swarm::ChannelMaps maps;
  swarm::BlobFeatureExtractor blob;
  for (const Scene& s : train) AddStage1Samples(s, t.rng, maps, t.o.blob_features ? &blob : nullptr, &s1, &centred);
  FitStage1(t, s1, centred);
  for (int round = 0; round < t.o.stage1_rounds; ++round) {
    AddStage1HardNegatives(t, train, round, &s1);
    FitStage1(t, s1, centred);
  }
  return Stage2Positives(t.model, s1);
}

// Stage 2 samples: the first stage's candidates on the training scenes, positives into *s2 and
// negatives into *neg.
void AddStage2Candidates(const Training& t, const std::vector<Scene>& train, Labelled* s2, Labelled* neg) {
  auto shared = std::make_shared<swarm::VictimDetectorModel>(t.model);
  swarm::VictimDetector first(shared, {});
  std::vector<float> g(static_cast<std::size_t>(t.model.forest_inputs()));
  for (const Scene& s : train) {
    const double ppm = PixelsPerMetre(s), scale = swarm::kCanonicalPxPerM / ppm;
    // Every local maximum, whatever its score (the first stage alone is precise on these scenes:
    // above its threshold too few negatives remain to teach the forest).
    const auto& cands = first.Candidates(BgrOf(s), ppm, kStage2CandidatesPerScene, -1e30);
    for (const auto& c : cands) {
      const Eigen::Vector2d centre(swarm::WindowCentreCanonical(0) + swarm::kShrink * c.sub_col,
                                   swarm::WindowCentreCanonical(0) + swarm::kShrink * c.sub_row);
      const auto [dist, must] = NearestPerson(s, scale, centre);
      int label = -1;
      if (dist <= kPositiveRadiusM && must) label = 1;
      if (dist >= kNegativeRadiusM) label = 0;
      if (label < 0) continue;
      first.ForestFeatures(c, g.data());
      Labelled& dst = label ? *s2 : *neg;
      dst.x.insert(dst.x.end(), g.begin(), g.end());
      dst.y.push_back(label);
    }
  }
}

// Stage 2's samples: the candidates' positives and a seeded sample of their negatives.
Status CollectStage2(Training& t, const std::vector<Scene>& train, Labelled* s2) {
  Labelled neg;
  AddStage2Candidates(t, train, s2, &neg);
  std::vector<int> order(static_cast<std::size_t>(neg.rows()));
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::shuffle(order.begin(), order.end(), t.rng);
  if (static_cast<int>(order.size()) > t.o.max_negatives) order.resize(static_cast<std::size_t>(t.o.max_negatives));
  t.report->stage2_positives = s2->rows();
  const std::ptrdiff_t inputs = t.model.forest_inputs();
  for (int i : order) {
    s2->x.insert(s2->x.end(), neg.x.begin() + i * inputs, neg.x.begin() + (i + 1) * inputs);
    s2->y.push_back(0);
  }
  t.report->stage2_negatives = static_cast<int>(order.size());
  std::fprintf(stderr, "train-detector: stage 2 on %d positives, %d negatives (of %d) (%.0f s)\n",
               t.report->stage2_positives, t.report->stage2_negatives, neg.rows(), Seconds(t.t0));
  if (t.report->stage2_positives < 50) {
    return Error(ErrorCode::kInternal, "train-detector: the first stage left fewer than 50 positives");
  }
  return Ok{};
}

Status TrainModelForest(Training& t, Labelled& s2) {
  Result<cv::Ptr<cv::ml::RTrees>> forest = TrainForest(s2, t.model.forest_inputs(), t.o);
  if (!forest) return forest.error();
  t.model.forest = *forest;
  t.model.FlattenForest();
  std::fprintf(stderr, "train-detector: forest on %d samples (%.0f s)\n", s2.rows(), Seconds(t.t0));
  return Ok{};
}

// One round of hard negatives (bootstrapping, Felzenszwalb et al. 2010): the detector on the
// training frames; its candidates at least 1.5 m from every person that the forest gives at least
// kHardNegativeVotes join the negatives.
void MineHardNegatives(Training& t, const std::vector<Scene>& train, int round, Labelled* s2) {
  auto mined = std::make_shared<swarm::VictimDetectorModel>(t.model);
  swarm::VictimDetectorParams raw;
  raw.min_confidence = 0.0;
  raw.partial_confidence_cap = 1.0;
  raw.nms_radius_m = 0.0;
  raw.max_candidates = t.o.max_candidates;
  swarm::VictimDetector det(mined, raw);
  std::vector<float> g(static_cast<std::size_t>(t.model.forest_inputs()));
  int hard = 0;
  for (const Scene& s : train) {
    const double ppm = PixelsPerMetre(s), scale = swarm::kCanonicalPxPerM / ppm;
    const auto& cands = det.Candidates(BgrOf(s), ppm, raw.max_candidates, t.model.stage1_threshold);
    for (const auto& c : cands) {
      const Eigen::Vector2d centre(swarm::WindowCentreCanonical(0) + swarm::kShrink * c.sub_col,
                                   swarm::WindowCentreCanonical(0) + swarm::kShrink * c.sub_row);
      if (NearestPerson(s, scale, centre).first < kNegativeRadiusM) continue;
      det.ForestFeatures(c, g.data());
      if (t.model.Votes(g.data()) < kHardNegativeVotes) continue;
      if (hard >= t.o.max_hard_negatives) break;
      s2->x.insert(s2->x.end(), g.begin(), g.end());
      s2->y.push_back(0);
      ++hard;
    }
  }
  t.report->stage2_hard_negatives += hard;
  std::fprintf(stderr, "train-detector: round %d: %d hard negatives (votes >= %.2f) (%.0f s)\n", round + 1, hard,
               kHardNegativeVotes, Seconds(t.t0));
  t.report->stage2_negatives = s2->rows() - t.report->stage2_positives;
}

// The flattened forest decides as OpenCV's own prediction.
Status CheckFlattenedForest(const Training& t, Labelled& s2) {
  cv::Mat x(s2.rows(), t.model.forest_inputs(), CV_32F, s2.x.data());
  cv::Mat votes;
  t.model.forest->getVotes(x, votes, 0);
  int person_col = votes.at<int>(0, 0) == 1 ? 0 : 1, disagree = 0;
  for (int i = 0; i < x.rows; ++i) {
    const double v = static_cast<double>(votes.at<int>(i + 1, person_col)) / t.o.forest_trees;
    disagree += std::abs(v - t.model.Votes(x.ptr<float>(i))) > 1e-9 ? 1 : 0;
  }
  if (disagree > 0) {
    return Error(ErrorCode::kInternal, "train-detector: the flattened forest disagrees with RTrees on " +
                                           std::to_string(disagree) + " samples");
  }
  return Ok{};
}

// The patch file (train_detector.hpp, kPatchFileMagic): records streamed out, the count written
// into the header by Close().
class PatchWriter {
 public:
  explicit PatchWriter(int patch_px) : patch_px_(patch_px) {}
  Status Open(const std::string& path) {
    path_ = path;
    out_.open(path, std::ios::binary | std::ios::trunc);
    if (!out_) return Error(ErrorCode::kIo, "train-detector: cannot write the patch file", path);
    const std::uint32_t header[3] = {kPatchFileVersion, static_cast<std::uint32_t>(patch_px_), 3};
    const auto px_per_m = static_cast<float>(patch_px_ / swarm::kCnnPatchM);
    const std::uint64_t count = 0;  // Close() writes the count here
    out_.write(kPatchFileMagic, sizeof(kPatchFileMagic));
    out_.write(reinterpret_cast<const char*>(header), sizeof(header));
    out_.write(reinterpret_cast<const char*>(&px_per_m), sizeof(px_per_m));
    out_.write(reinterpret_cast<const char*>(&count), sizeof(count));
    return Ok{};
  }
  void Add(const cv::Mat& patch, int label, PatchSplit split) {
    SWARMBOX_CHECK(patch.type() == CV_8UC3 && patch.isContinuous() && patch.rows == patch_px_ &&
                   patch.cols == patch_px_);
    const char record[2] = {static_cast<char>(label), static_cast<char>(split)};
    out_.write(record, sizeof(record));
    out_.write(reinterpret_cast<const char*>(patch.data), static_cast<std::streamsize>(patch.total() * patch.elemSize()));
    ++count_;
    ++(split == PatchSplit::kTraining ? training_ : calibration_)[label ? 1 : 0];
  }
  Status Close() {
    constexpr std::streamoff kCountOffset = sizeof(kPatchFileMagic) + 4 * sizeof(std::uint32_t);
    out_.seekp(kCountOffset);
    out_.write(reinterpret_cast<const char*>(&count_), sizeof(count_));
    out_.close();
    if (!out_) return Error(ErrorCode::kIo, "train-detector: writing the patch file failed", path_);
    std::fprintf(stderr, "train-detector: %llu patches: training %d persons, %d not; calibration %d persons, %d not\n",
                 static_cast<unsigned long long>(count_), training_[1], training_[0], calibration_[1], calibration_[0]);
    return Ok{};
  }

 private:
  int patch_px_;
  std::ofstream out_;
  std::string path_;
  std::uint64_t count_ = 0;
  int training_[2] = {0, 0};  // [no person, person]
  int calibration_[2] = {0, 0};
};

// One scene's patches: its first-stage local maxima (the best kStage2CandidatesPerScene, any score)
// labelled as the forest's samples are, and on training frames each must-detect person's own centre
// as a positive too (the first stage's centred positives).
void AddScenePatches(swarm::VictimDetector& det, const Scene& s, PatchSplit split, PatchWriter* w) {
  const double ppm = PixelsPerMetre(s), scale = swarm::kCanonicalPxPerM / ppm;
  cv::Mat patch;
  for (const auto& c : det.Candidates(BgrOf(s), ppm, kStage2CandidatesPerScene, -1e30)) {
    const Eigen::Vector2d centre(swarm::WindowCentreCanonical(0) + swarm::kShrink * c.sub_col,
                                 swarm::WindowCentreCanonical(0) + swarm::kShrink * c.sub_row);
    const auto [dist, must] = NearestPerson(s, scale, centre);
    const int label = dist <= kPositiveRadiusM && must ? 1 : dist >= kNegativeRadiusM ? 0 : -1;
    if (label < 0) continue;
    det.CnnPatch(c, &patch);
    w->Add(patch, label, split);
  }
  if (split != PatchSplit::kTraining) return;
  swarm::CandidatePatchSampler sampler(det.model().cnn_patch_px);
  sampler.SetFrame(BgrOf(s), ppm);
  for (const SceneVictim& v : s.victims) {
    const std::optional<Eigen::Vector2d> px =
        swarm::ProjectToPixel(Eigen::Vector3d(v.position_m.x(), v.position_m.y(), 0.0), s.intrinsics, s.true_pose);
    if (v.visible_fraction < kMustDetectFraction || !px) continue;
    sampler.Extract(*px, &patch);
    w->Add(patch, 1, split);
  }
}

// The CNN's patches of the training and calibration frames into `path`, with the first stage of
// t.model.
Status ExportPatches(const Training& t, const std::vector<Scene>& train, const std::vector<Scene>& cal,
                     const std::string& path) {
  auto shared = std::make_shared<swarm::VictimDetectorModel>(t.model);
  shared->cnn_patch_px = t.o.cnn_patch_px;
  swarm::VictimDetector det(shared, {});
  PatchWriter w(t.o.cnn_patch_px);
  SWARMBOX_TRY(w.Open(path));
  for (const Scene& s : train) AddScenePatches(det, s, PatchSplit::kTraining, &w);
  for (const Scene& s : cal) AddScenePatches(det, s, PatchSplit::kCalibration, &w);
  SWARMBOX_TRY(w.Close());
  std::fprintf(stderr, "train-detector: wrote %s (%.0f s)\n", path.c_str(), Seconds(t.t0));
  return Ok{};
}

// Runs the CNN training script (argv, no shell) and waits for it.
Status RunCnnScript(const TrainingOptions& o, const std::string& patches, const std::string& onnx) {
  std::vector<std::string> args = {o.python,
                                   o.cnn_script,
                                   "--patches",
                                   patches,
                                   "--out",
                                   onnx,
                                   "--seed",
                                   std::to_string(o.cnn_seed),
                                   "--epochs",
                                   std::to_string(o.cnn_epochs),
                                   "--widths",
                                   o.cnn_widths,
                                   "--negatives-per-epoch",
                                   std::to_string(o.cnn_negatives_per_epoch),
                                   "--hard-fraction",
                                   std::to_string(o.cnn_hard_fraction)};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string install = " (python3-torch: scripts/setup_training.sh installs it)";
  pid_t pid = 0;
  if (const int rc = posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ); rc != 0) {
    return Error(ErrorCode::kNotFound, "train-detector: cannot run " + o.python + ": " + std::strerror(rc) + install);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    return Error(ErrorCode::kInternal, "train-detector: " + o.cnn_script + " failed" + install);
  }
  return Ok{};
}

// The CNN second stage: patches exported, the script run, its ONNX into the model (checked to load
// in cv::dnn); the forest dropped.
Status TrainCnnStage(Training& t, const std::vector<Scene>& train, const std::vector<Scene>& cal) {
  const std::string patches = t.o.export_patches.empty() ? t.o.cnn_onnx_out + ".patches" : t.o.export_patches;
  SWARMBOX_TRY(ExportPatches(t, train, cal, patches));
  SWARMBOX_TRY(RunCnnScript(t.o, patches, t.o.cnn_onnx_out));
  t.model.cnn_patch_px = t.o.cnn_patch_px;
  t.model.cnn_symmetries = t.o.cnn_symmetries > 0 ? t.o.cnn_symmetries : 1;
  SWARMBOX_TRY(ReadCnn(t.o.cnn_onnx_out, &t.model.cnn_onnx));
  t.model.forest.release();
  std::fprintf(stderr, "train-detector: CNN of %zu bytes (%.0f s)\n", t.model.cnn_onnx.size(), Seconds(t.t0));
  return Ok{};
}

// The forest second stage (the shipped recipe): samples, forest, hard-negative rounds, check.
Status TrainForestStage(Training& t, const std::vector<Scene>& train, Labelled& s2) {
  SWARMBOX_TRY(CollectStage2(t, train, &s2));
  SWARMBOX_TRY(TrainModelForest(t, s2));
  // Hard negatives, hard_negative_rounds times, each followed by the forest trained again.
  for (int round = 0; round < t.o.hard_negative_rounds; ++round) {
    MineHardNegatives(t, train, round, &s2);
    SWARMBOX_TRY(TrainModelForest(t, s2));
  }
  return CheckFlattenedForest(t, s2);
}

}  // namespace

namespace {

// Every training set (the mixed terrains, then the cones-and-rubble and the rubble-field sets),
// each within --view-altitudes when given.
Result<std::vector<Scene>> RenderTrainingSets(const TrainingOptions& o) {
  auto band = [&o](perception_scenes::SceneSetParams p) {
    if (o.view_min_altitude_m > 0) {
      p.min_altitude_m = o.view_min_altitude_m;
      p.max_altitude_m = o.view_max_altitude_m;
    }
    return p;
  };
  Result<std::vector<Scene>> train =
      RenderSets(o.training_seeds, o.scenes_per_set,
                 [&](std::uint64_t seed, int scenes) { return band(TrainingSceneSet(seed, scenes)); });
  if (!train) return train.error();
  auto add = [&](const std::vector<std::uint64_t>& seeds, auto set_params) -> Status {
    Result<std::vector<Scene>> extra = RenderSets(seeds, o.scenes_per_set, set_params);
    if (!extra) return extra.error();
    for (Scene& x : *extra) train->push_back(std::move(x));
    return Ok{};
  };
  SWARMBOX_TRY(add(NegativesSeeds(o),
                   [&](std::uint64_t seed, int scenes) { return band(NegativesSceneSet(seed, scenes)); }));
  SWARMBOX_TRY(add(WorldSeeds(o), [&](std::uint64_t seed, int scenes) {
    return band(WorldSceneSet(seed, scenes, o.world_distractors));
  }));
  return train;
}

}  // namespace

Result<swarm::VictimDetectorModel> Train(const TrainingOptions& o, TrainingReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  SWARMBOX_TRY(CheckTrainingOptions(o));
  Result<std::vector<Scene>> train = RenderTrainingSets(o);
  if (!train) return train.error();
  Result<std::vector<Scene>> cal = RenderCalibrationSets(o);
  if (!cal) return cal.error();
  report->training_scenes = static_cast<int>(train->size());
  report->calibration_scenes = static_cast<int>(cal->size());
  std::fprintf(stderr, "train-detector: rendered %d training and %d calibration scenes (%.0f s)\n",
               report->training_scenes, report->calibration_scenes, Seconds(t0));
  Training t{.o = o, .report = report, .t0 = t0};
  Labelled s2 = TrainStage1(t, *train);
  if (!o.cnn_script.empty()) {
    SWARMBOX_TRY(TrainCnnStage(t, *train, *cal));
  } else {
    if (!o.export_patches.empty()) SWARMBOX_TRY(ExportPatches(t, *train, *cal, o.export_patches));
    SWARMBOX_TRY(TrainForestStage(t, *train, s2));
  }
  if (Status st = Calibrate(*cal, o, &t.model, report); !st) return st.error();
  SWARMBOX_TRY(CalibrateClose(*cal, o, &t.model));
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t.model;
}

namespace {

// The report's one-line description of the model's method.
std::string MethodText(const swarm::VictimDetectorModel& model) {
  std::string text =
      "aggregated channel features (Luv, gradient magnitude, 4 orientations; 0.25 m cells, 3 x 3 m windows at "
      "8 px/m), ridge linear first stage, cv::ml::RTrees second stage";
  if (model.blob_features > 0) {
    text += " on the window, the first-stage score and " + std::to_string(model.blob_features) +
            " blob features (size, shape, parts, edge orientations; 16 px/m)";
  }
  if (model.has_cnn()) {
    const std::string px = std::to_string(model.cnn_patch_px);
    text +=
        " replaced by a CNN on " + px + " x " + px +
        " colour patches (3 x 3 m) run by cv::dnn (train_cnn.py; the recipe's "
        "--cnn-widths: its blocks' channels; --cnn-hard-fraction: the share of each epoch's negatives from "
        "the hardest mined)";
  }
  return text + ", Platt sigmoid";
}

}  // namespace

namespace {

// The sigmoids (and the close-look CNN's size) as one JSON object, on one line: a recalibration's
// report takes it with the first sigmoid.
std::string PlattJson(const swarm::VictimDetectorModel& model) {
  std::ostringstream j;
  j << "{\"a\": " << model.platt_a << ", \"b\": " << model.platt_b;
  if (model.close_px_per_m > 0) {
    j << ", \"close\": {\"a\": " << model.close_platt_a << ", \"b\": " << model.close_platt_b
      << ", \"from_px_per_m\": " << model.close_px_per_m;
    if (model.has_close_cnn()) {
      j << ", \"close_cnn_patch_px\": " << model.close_cnn_patch_px
        << ", \"close_cnn_bytes\": " << model.close_cnn_onnx.size();
    }
    j << "}";
  }
  j << "}";
  return j.str();
}

}  // namespace

std::string ReportJson(const swarm::VictimDetectorModel& model, const TrainingOptions& o,
                       const TrainingReport& r, const std::string& model_file) {
  std::ostringstream j;
  auto list = [&](const std::vector<std::uint64_t>& v) {
    j << "[";
    for (std::size_t i = 0; i < v.size(); ++i) j << (i ? ", " : "") << v[i];
    j << "]";
  };
  j << "{\n  \"model\": \"" << model_file << "\",\n";
  j << "  \"method\": \"" << MethodText(model) << "\",\n";
  j << "  \"recipe\": \"" << model.recipe << "\",\n";
  j << "  \"training_seeds\": ";
  list(model.training_seeds);
  j << ",\n  \"calibration_seeds\": ";
  list(model.calibration_seeds);
  j << ",\n  \"scenes_per_set\": " << o.scenes_per_set << ",\n";
  j << "  \"training_scenes\": " << r.training_scenes << ",\n  \"calibration_scenes\": " << r.calibration_scenes << ",\n";
  j << "  \"stage1\": {\"positives\": " << r.stage1_positives << ", \"negatives\": " << r.stage1_negatives
    << ", \"threshold\": " << model.stage1_threshold << ", \"threshold_percentile\": " << o.stage1_percentile
    << ", \"ridge_lambda\": " << o.ridge_lambda << "},\n";
  j << "  \"stage1_calibration_recall\": " << r.stage1_calibration_recall << ",\n";
  j << "  \"stage2\": {\"positives\": " << r.stage2_positives << ", \"negatives\": " << r.stage2_negatives
    << ", \"balance_classes\": " << (o.balance_classes ? "true" : "false") << ", \"hard_negative_rounds\": "
    << o.hard_negative_rounds << ", \"hard_negatives\": " << r.stage2_hard_negatives << ", \"trees\": " << o.forest_trees << ", \"max_depth\": " << o.forest_depth << "},\n";
  j << "  \"platt\": " << PlattJson(model) << ",\n";
  j << "  \"calibration_figures\": {\"persons_at_least_half_visible\": " << r.calibration_persons
    << ", \"detections_labelled\": " << r.calibration_detections << ", \"tp_at_0.5\": " << r.calibration_tp
    << ", \"fp_at_0.5\": " << r.calibration_fp << ", \"precision_at_0.5\": " << r.precision
    << ", \"recall_at_0.5\": " << r.recall << "},\n";
  j << "  \"training_seconds\": " << r.seconds << "\n}\n";
  return j.str();
}

}  // namespace swarmbox::train_detector
