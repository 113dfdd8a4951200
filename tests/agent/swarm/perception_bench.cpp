// swarmbox-bench perception [--seed N] [--scenes K] [--quick] [--model FILE]: the detector's figures
// on physics-rendered scenes of seed N (never a training or calibration seed of the model: refused),
// of the shipped model or of a model file train-detector wrote elsewhere (--model: the curves only,
// to compare a recipe before shipping it; --only altitude:30 runs one case; --max-candidates N
// the first stage's cap instead of VictimDetectorParams' default), in the
// varied look (perception_scenes.hpp: terrains, light, poses, clothing, cover, distractors), one
// logfmt line per case:
//   case=altitude     altitude_m=10|20|30|40|60 (30 % of the people partly covered, 2 distractors each)
//   case=occlusion    occluded_fraction=0|0.5|1 at 30 m (share of the people under 20-80 % cover)
//   case=distractors  distractors=0|2|6 per person at 30 m
// with persons (at least half visible), tp, fp, precision and recall at confidence 0.5, ap (VOC,
// all detections), recall_at_p90 (the highest recall at precision >= 0.9, any confidence: a point
// of the curve, not an operating point), max_recall (all detections) and ms_per_frame (Detect() on
// one core: cv::setNumThreads(1)); then the pipeline scenarios (latency queue, geolocation with
// estimated poses, tilted cameras) as before.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>

#include <opencv2/core.hpp>

#include "bench.hpp"
#include "perception_score.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace {

using namespace swarmbox::swarm;
using namespace swarmbox::swarm::testing;

struct Scenario {
  std::string name;
  SceneSetParams scenes;
  PoseNoise pose;
  double tilt_differential = 0.0;  // > 0: RenderTiltedScenes with this rotor differential
  bool acceptance = true;          // false: a stress case, reported only
};

struct CurveCase {
  std::string kind;
  std::string key;
  double value;
  SceneSetParams scenes;
};

int RunCurves(const swarmbox::bench::Args& args, std::uint64_t seed,
              const std::shared_ptr<const VictimDetectorModel>& model) {
  const int n = args.quick ? 12 : static_cast<int>(args.GetInt("scenes", 240));
  auto at = [&](double altitude, double occluded, int distractors) {
    return SceneSetParams{.seed = seed, .scenes = n, .scenes_per_world = 12, .min_altitude_m = altitude,
                          .max_altitude_m = altitude, .near_victim_fraction = 0.85, .near_victim_offset = 1.0,
                          .occluded_fraction = occluded, .distractors = distractors, .varied_look = true};
  };
  std::vector<CurveCase> cases;
  for (double a : {10.0, 20.0, 30.0, 40.0, 60.0}) cases.push_back({"altitude", "altitude_m", a, at(a, 0.3, 2)});
  for (double o : {0.0, 0.5, 1.0}) cases.push_back({"occlusion", "occluded_fraction", o, at(30, o, 2)});
  for (int d : {0, 2, 6}) cases.push_back({"distractors", "distractors", static_cast<double>(d), at(30, 0.3, d)});
  if (args.quick) cases.resize(2);
  // --only KIND:VALUE (e.g. altitude:30, distractors:0): that case alone.
  if (const std::string only = args.Get("only", ""); !only.empty()) {
    std::erase_if(cases, [&](const CurveCase& c) {
      char name[64];
      std::snprintf(name, sizeof name, "%s:%g", c.kind.c_str(), c.value);
      return only != name;
    });
    if (cases.empty()) {
      std::fprintf(stderr, "perception bench: --only %s names no case (altitude:10|20|30|40|60, occlusion:0|0.5|1, "
                   "distractors:0|2|6)\n", only.c_str());
      return 2;
    }
  }
  cv::setNumThreads(1);
  VictimDetectorParams params;
  params.max_candidates = static_cast<int>(args.GetInt("max-candidates", params.max_candidates));
  VictimDetector detector(model, params);
  for (const CurveCase& c : cases) {
    swarmbox::Result<std::vector<Scene>> scenes = RenderScenes(c.scenes);
    if (!scenes) {
      std::fprintf(stderr, "perception bench: %s\n", scenes.error().ToString().c_str());
      return 1;
    }
    const DetectionCurve d = ScoreDetections(*scenes, detector);
    swarmbox::LogEvent line(0.0, "bench", "bench_result");
    line.Add("suite", "perception").Add("case", c.kind).Add("seed", seed);
    line.Add(c.key, c.value, c.key == "occluded_fraction" ? 1 : 0);
    if (c.kind != "altitude") line.Add("altitude_m", 30);
    line.Add("scenes", d.scenes)
        .Add("persons", d.persons)
        .Add("tp", d.tp)
        .Add("fp", d.fp)
        .Add("precision", d.precision, 4)
        .Add("recall", d.recall, 4)
        .Add("ap", d.ap, 4)
        .Add("recall_at_p90", d.recall_at_precision_90, 4)
        .Add("max_recall", d.max_recall, 4)
        .Add("ms_per_frame", d.ms_per_frame, 2);
    std::puts(line.str().c_str());
  }
  cv::setNumThreads(-1);
  return 0;
}

int RunPerceptionBench(const swarmbox::bench::Args& args) {
  const auto seed = static_cast<std::uint64_t>(args.GetInt("seed", 20261121));
  std::shared_ptr<const VictimDetectorModel> model = ShippedDetectorModel();
  const auto model_file = args.options.find("model");
  if (model_file != args.options.end()) {
    swarmbox::Result<std::shared_ptr<const VictimDetectorModel>> loaded = LoadDetectorModel(model_file->second);
    if (!loaded) {
      std::fprintf(stderr, "perception bench: %s\n", loaded.error().ToString().c_str());
      return 2;
    }
    model = *loaded;
  }
  for (const auto* list : {&model->training_seeds, &model->calibration_seeds}) {
    if (std::find(list->begin(), list->end(), seed) != list->end()) {
      std::fprintf(stderr, "perception bench: seed %llu is one the detector was trained or calibrated on\n",
                   static_cast<unsigned long long>(seed));
      return 2;
    }
  }
  if (int rc = RunCurves(args, seed, model); rc != 0) return rc;
  // The pipeline scenarios run the shipped model (VictimPerception): a --model file gets the curves.
  if (args.GetInt("curves_only", 0) != 0 || model_file != args.options.end()) return 0;
  const int n = args.quick ? 48 : static_cast<int>(args.GetInt("scenes", 320));
  const double latency_s = args.GetDouble("latency_s", 0.040);
  const PoseNoise estimated{.seed = 3, .position_sigma_m = 0.3, .attitude_sigma_rad = 0.5 * std::numbers::pi / 180};
  const Scenario scenarios[] = {
      {"mixed_10_40m", {.seed = 20261121, .scenes = n}, {}},
      {"mixed_10_40m_est_pose", {.seed = 20261121, .scenes = n}, estimated},
      {"nadir_30m", {.seed = 30, .scenes = n, .min_altitude_m = 30, .max_altitude_m = 30, .near_victim_fraction = 1.0}, {}},
      {"nadir_30m_est_pose", {.seed = 30, .scenes = n, .min_altitude_m = 30, .max_altitude_m = 30, .near_victim_fraction = 1.0}, estimated},
      {"high_noise_40m", {.seed = 40, .scenes = n, .min_altitude_m = 38, .max_altitude_m = 40, .min_noise_std = 12, .max_noise_std = 16}, {}, 0.0, false},
      {"tilt_to_15deg", {.seed = 77, .scenes = n, .scenes_per_world = 32, .min_altitude_m = 15, .max_altitude_m = 35}, {}, 0.015},
      {"tilt_to_70deg", {.seed = 78, .scenes = n, .scenes_per_world = 32, .min_altitude_m = 15, .max_altitude_m = 35}, {}, 0.06, false},
  };
  int rc = 0;
  for (const Scenario& sc : scenarios) {
    const auto t0 = std::chrono::steady_clock::now();
    swarmbox::Result<std::vector<Scene>> scenes =
        sc.tilt_differential > 0 ? RenderTiltedScenes(sc.scenes, sc.tilt_differential, 0.25)
                                 : RenderScenes(sc.scenes);
    if (!scenes) {
      std::fprintf(stderr, "perception bench: %s\n", scenes.error().ToString().c_str());
      return 1;
    }
    const auto t1 = std::chrono::steady_clock::now();
    PerceptionParams params;
    params.latency_s = latency_s;
    const PerceptionScore s = ScorePerception(*scenes, params, sc.pose);
    double max_tilt = 0;
    for (const Scene& x : *scenes) max_tilt = std::max(max_tilt, x.tilt_rad);
    const auto t2 = std::chrono::steady_clock::now();
    const double per_frame_ms = 1e3 * std::chrono::duration<double>(t2 - t1).count() / s.scenes;
    const double render_ms = 1e3 * std::chrono::duration<double>(t1 - t0).count() / s.scenes;
    std::puts(swarmbox::LogEvent(0.0, "bench", "bench_result")
                  .Add("suite", "perception")
                  .Add("scenario", sc.name)
                  .Add("scenes", s.scenes)
                  .Add("max_tilt_deg", max_tilt * 180 / std::numbers::pi, 1)
                  .Add("acceptance", sc.acceptance)
                  .Add("victims_full", s.full_victims)
                  .Add("victims_partial", s.partial_victims)
                  .Add("tp", s.true_positives)
                  .Add("fp", s.false_positives)
                  .Add("partial_detected", s.partial_detected)
                  .Add("precision", s.precision(), 4)
                  .Add("recall", s.recall(), 4)
                  .Add("geo_err_median_m", s.median_error_m(), 3)
                  .Add("geo_err_p90_m", s.p90_error_m(), 3)
                  .Add("latency_ms", 1e3 * latency_s, 1)
                  .Add("pipeline_ms_per_frame", per_frame_ms, 3)
                  .Add("render_ms_per_scene", render_ms, 2)
                  .str()
                  .c_str());
    if (sc.acceptance && (s.precision() < 0.95 || s.recall() < 0.95)) rc = 1;
    if (sc.name.rfind("nadir_30m", 0) == 0 && s.median_error_m() >= 1.0) rc = 1;
  }
  return rc;
}

}  // namespace

SWARMBOX_BENCH_SUITE(perception, "Victim detection on physics-rendered frames: precision, recall, geolocation",
                     RunPerceptionBench);
