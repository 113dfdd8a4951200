#include "perception_score.hpp"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <random>
#include <utility>

#include <opencv2/core.hpp>

namespace swarmbox::swarm::testing {

using Eigen::Vector2d;
using Eigen::Vector3d;

double PerceptionScore::precision() const {
  const int positives = true_positives + false_positives;
  return positives == 0 ? 1.0 : static_cast<double>(true_positives) / positives;
}
double PerceptionScore::recall() const {
  return full_victims == 0 ? 1.0 : static_cast<double>(true_positives) / full_victims;
}
static double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::floor(q * static_cast<double>(v.size() - 1) + 0.5));
  return v[i];
}
double PerceptionScore::median_error_m() const { return Quantile(errors_m, 0.5); }
double PerceptionScore::p90_error_m() const { return Quantile(errors_m, 0.9); }

PerceptionScore ScorePerception(const std::vector<Scene>& scenes, const PerceptionParams& params,
                                const PoseNoise& noise, double match_radius_m) {
  PerceptionScore score;
  VictimPerception perception(params);
  std::mt19937_64 rng(noise.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<GroundDetection> ready;
  double t = 0.0;
  for (const Scene& s : scenes) {
    ++score.scenes;
    OpticalPose est = s.true_pose;
    est.position_m += noise.position_sigma_m * Vector3d(n01(rng), n01(rng), n01(rng));
    const Vector3d rv = noise.attitude_sigma_rad * Vector3d(n01(rng), n01(rng), n01(rng));
    if (rv.norm() > 0) est.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(rv.norm(), rv.normalized())) * est.rotation;
    cv::Mat bgr(s.image.height_px, s.image.width_px, CV_8UC3, const_cast<std::uint8_t*>(s.image.bgr.data()));
    perception.ProcessFrame(bgr, s.intrinsics, est, t);
    ready.clear();
    perception.PopVisible(t + params.latency_s, &ready);
    t += 1.0;
    std::vector<bool> matched(s.victims.size(), false);
    for (const SceneVictim& v : s.victims) {
      score.full_victims += v.visibility == Visibility::kFull ? 1 : 0;
      score.partial_victims += v.visibility == Visibility::kPartial ? 1 : 0;
    }
    for (const GroundDetection& d : ready) {
      std::size_t best = s.victims.size();
      double best_d = match_radius_m;
      for (std::size_t i = 0; i < s.victims.size(); ++i) {
        if (s.victims[i].visibility == Visibility::kAbsent) continue;
        const double e = (s.victims[i].position_m - d.position_m.head<2>()).norm();
        if (e <= best_d) {
          best_d = e;
          best = i;
        }
      }
      if (best == s.victims.size()) {
        ++score.false_positives;
      } else if (s.victims[best].visibility == Visibility::kPartial) {
        ++score.partial_detected;
      } else if (!matched[best]) {
        matched[best] = true;
        ++score.true_positives;
        score.errors_m.push_back(best_d);
      } else {
        ++score.false_positives;  // a second detection of the same victim
      }
    }
  }
  return score;
}

DetectionCurve ScoreDetections(const std::vector<Scene>& scenes, VictimDetector& detector,
                               double operating_point, double must_fraction, double match_radius_m,
                               const MissFn& on_miss) {
  DetectionCurve curve;
  std::vector<std::pair<double, int>> ranked;  // (confidence, 1 true / 0 false positive)
  std::vector<ImageBlob> blobs;
  double seconds = 0;
  for (const Scene& s : scenes) {
    ++curve.scenes;
    const cv::Mat bgr(s.image.height_px, s.image.width_px, CV_8UC3, const_cast<std::uint8_t*>(s.image.bgr.data()));
    const auto t0 = std::chrono::steady_clock::now();
    detector.Detect(bgr, s.intrinsics, s.true_pose, 0.0, &blobs);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (const SceneVictim& v : s.victims) curve.persons += v.visible_fraction >= must_fraction ? 1 : 0;
    std::vector<bool> matched(s.victims.size(), false);
    std::vector<double> best_confidence(s.victims.size(), 0.0);
    for (const ImageBlob& b : blobs) {  // most confident first (the detector's order)
      const std::optional<Vector3d> g = PixelToGround(b.centroid_px, s.intrinsics, s.true_pose, 0.0);
      std::size_t best = s.victims.size();
      double best_d = match_radius_m;
      if (g) {
        for (std::size_t i = 0; i < s.victims.size(); ++i) {
          if (s.victims[i].visible_fraction <= 0) continue;
          const double e = (s.victims[i].position_m - g->head<2>()).norm();
          if (e <= best_d) {
            best_d = e;
            best = i;
          }
        }
      }
      if (best < s.victims.size() && s.victims[best].visible_fraction < must_fraction) continue;  // not scored
      const bool tp = best < s.victims.size() && !matched[best];
      if (tp) matched[best] = true;
      if (best < s.victims.size()) best_confidence[best] = std::max(best_confidence[best], b.confidence);
      ranked.emplace_back(b.confidence, tp ? 1 : 0);
    }
    for (std::size_t i = 0; on_miss && i < s.victims.size(); ++i) {
      if (s.victims[i].visible_fraction >= must_fraction && best_confidence[i] < operating_point) {
        on_miss(s, s.victims[i], best_confidence[i]);
      }
    }
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  // VOC AP: precision made monotone from the right, integrated over recall.
  std::vector<double> prec, rec;
  int tp = 0, fp = 0;
  for (const auto& [conf, t] : ranked) {
    (t ? tp : fp) += 1;
    prec.push_back(static_cast<double>(tp) / (tp + fp));
    rec.push_back(curve.persons ? static_cast<double>(tp) / curve.persons : 0.0);
    if (conf >= operating_point) {
      curve.tp = tp;
      curve.fp = fp;
    }
  }
  for (std::size_t i = prec.size(); i-- > 1;) prec[i - 1] = std::max(prec[i - 1], prec[i]);
  double last_r = 0;
  for (std::size_t i = 0; i < prec.size(); ++i) {
    curve.ap += (rec[i] - last_r) * prec[i];
    last_r = rec[i];
    if (prec[i] >= 0.9) curve.recall_at_precision_90 = std::max(curve.recall_at_precision_90, rec[i]);
  }
  curve.max_recall = last_r;
  curve.precision = curve.tp + curve.fp ? static_cast<double>(curve.tp) / (curve.tp + curve.fp) : 1.0;
  curve.recall = curve.persons ? static_cast<double>(curve.tp) / curve.persons : 1.0;
  curve.ms_per_frame = curve.scenes ? 1e3 * seconds / curve.scenes : 0.0;
  return curve;
}

}  // namespace swarmbox::swarm::testing
