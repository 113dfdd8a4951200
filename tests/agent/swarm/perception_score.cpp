#include "perception_score.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <utility>

#include <opencv2/core.hpp>

#include "swarmbox/common/split.hpp"
#include "swarmbox/common/yaml.hpp"

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

namespace {

// The blobs' confidences moved by the thermal evidence at their ground points (VictimPerception's
// rule, ThermalFusion), most confident first again.
void WithThermalEvidence(const Scene& s, ThermalFusion& fusion, std::vector<ImageBlob>* blobs) {
  const ThermalView view = perception_scenes::ThermalViewOf(*s.thermal);
  for (ImageBlob& b : *blobs) {
    const std::optional<Vector3d> g = PixelToGround(b.centroid_px, s.intrinsics, s.true_pose, 0.0);
    if (g) b.confidence = fusion.Apply(b.confidence, view, *g);
  }
  std::stable_sort(blobs->begin(), blobs->end(),
                   [](const ImageBlob& a, const ImageBlob& b) { return a.confidence > b.confidence; });
}

}  // namespace

DetectionCurve ScoreDetections(const std::vector<Scene>& scenes, VictimDetector& detector,
                               double operating_point, double must_fraction, double match_radius_m,
                               const MissFn& on_miss, const ThermalEvidence* thermal) {
  DetectionCurve curve;
  std::vector<std::pair<double, int>> ranked;  // (confidence, 1 true / 0 false positive)
  std::vector<ImageBlob> blobs;
  double seconds = 0;
  std::optional<ThermalFusion> fusion;
  if (thermal != nullptr) fusion.emplace(*thermal);
  for (const Scene& s : scenes) {
    ++curve.scenes;
    const cv::Mat bgr(s.image.height_px, s.image.width_px, CV_8UC3, const_cast<std::uint8_t*>(s.image.bgr.data()));
    const auto t0 = std::chrono::steady_clock::now();
    detector.Detect(bgr, s.intrinsics, s.true_pose, 0.0, &blobs);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (fusion && s.thermal) WithThermalEvidence(s, *fusion, &blobs);
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

void CloseLookTally::Add(const CloseLookTally& o) {
  real_candidates += o.real_candidates;
  false_candidates += o.false_candidates;
  real_looks += o.real_looks;
  real_detected += o.real_detected;
  false_looks += o.false_looks;
  false_detected += o.false_detected;
  for (std::size_t i = 0; i < kBins; ++i) {
    real_bins[i] += o.real_bins[i];
    false_bins[i] += o.false_bins[i];
  }
}

std::vector<DecidedCandidate> DecidedCandidates(const std::vector<LogfmtFields>& log_lines,
                                                const std::vector<Vector2d>& victims, double real_radius_m) {
  std::map<std::uint32_t, const LogfmtFields*> last;  // candidate id -> its last decision
  for (const LogfmtFields& f : log_lines) {
    const auto event = FindField(f, "event");
    if (event != std::optional<std::string>("confirmed") && event != std::optional<std::string>("rejected"))
      continue;
    const auto id = yaml::ScalarAsDouble(FindField(f, "candidate").value_or(""));
    if (id && *id >= 0) last[static_cast<std::uint32_t>(*id)] = &f;
  }
  std::vector<DecidedCandidate> out;
  for (const auto& [id, f] : last) {
    const auto x = yaml::ScalarAsDouble(FindField(*f, "x").value_or(""));
    const auto y = yaml::ScalarAsDouble(FindField(*f, "y").value_or(""));
    const std::string drone_list = FindField(*f, "drones").value_or("");
    const std::string confidence_list = FindField(*f, "confidences").value_or("");
    const std::string viewer_list = FindField(*f, "viewers").value_or("");
    const std::string time_list = FindField(*f, "view_t").value_or("");
    const std::vector<std::string_view> drones = SplitOn(drone_list, ',');
    const std::vector<std::string_view> confidences = SplitOn(confidence_list, ',');
    const std::vector<std::string_view> viewers = SplitOn(viewer_list, ',');
    const std::vector<std::string_view> times = SplitOn(time_list, ',');
    const std::size_t n = confidences.size();
    if (!x || !y || viewers.size() != n || drones.size() != n || times.size() != n) continue;  // not evidence
    DecidedCandidate d;
    d.candidate.id = id;
    d.candidate.x_m = *x;
    d.candidate.y_m = *y;
    d.confirmed = FindField(*f, "event") == std::optional<std::string>("confirmed");
    d.real = std::any_of(victims.begin(), victims.end(),
                         [&](const Vector2d& v) { return (v - Vector2d(*x, *y)).norm() <= real_radius_m; });
    bool complete = true;
    for (std::size_t i = 0; i < n && complete; ++i) {
      const std::vector<std::string_view> xyh = SplitOn(viewers[i], ':');
      const auto confidence = yaml::ScalarAsDouble(confidences[i]);
      const auto t = yaml::ScalarAsDouble(times[i]);
      std::optional<double> vx, vy, vh;
      if (xyh.size() == 3) {
        vx = yaml::ScalarAsDouble(xyh[0]);
        vy = yaml::ScalarAsDouble(xyh[1]);
        vh = yaml::ScalarAsDouble(xyh[2]);
      }
      complete = confidence && t && vx && vy && vh;
      if (!complete) break;
      raft::SightingView v;
      v.reporter = std::string(drones[i]);
      v.seq = i + 1;
      v.x_m = *x;
      v.y_m = *y;
      v.detected = *confidence > 0;
      v.confidence = *confidence;
      v.viewer_x_m = *vx;
      v.viewer_y_m = *vy;
      v.viewer_height_m = *vh;
      v.t_s = *t;
      d.candidate.views.push_back(std::move(v));
    }
    if (complete) out.push_back(std::move(d));
  }
  return out;
}

CloseLookTally TallyCloseLooks(const std::vector<DecidedCandidate>& decided, double close_height_m) {
  CloseLookTally t;
  for (const DecidedCandidate& d : decided) {
    (d.real ? t.real_candidates : t.false_candidates) += 1;
    for (const raft::SightingView& v : d.candidate.views) {
      if (v.viewer_height_m > close_height_m) continue;
      (d.real ? t.real_looks : t.false_looks) += 1;
      if (!v.detected) continue;
      (d.real ? t.real_detected : t.false_detected) += 1;
      const auto bin =
          static_cast<std::size_t>(std::clamp(static_cast<int>(std::floor((v.confidence - 0.5) * 10)), 0,
                                              static_cast<int>(CloseLookTally::kBins) - 1));
      (d.real ? t.real_bins : t.false_bins)[bin] += 1;
    }
  }
  return t;
}

void Redecision::Add(const Redecision& o) {
  real_confirmed += o.real_confirmed;
  real_rejected += o.real_rejected;
  real_open += o.real_open;
  false_confirmed += o.false_confirmed;
  false_rejected += o.false_rejected;
  false_open += o.false_open;
  same += o.same;
}

Redecision Redecide(const std::vector<DecidedCandidate>& decided, const FusionParams& params) {
  Redecision r;
  for (const DecidedCandidate& d : decided) {
    raft::Candidate c = d.candidate;
    c.views.clear();
    FusionDecision decision = FusionDecision::kNone;
    std::uint32_t close_looks = 0;
    for (const raft::SightingView& v : d.candidate.views) {
      c.views.push_back(v);
      close_looks += CloseLook(v, params) ? 1u : 0u;
      c.revisits =
          params.close_look_height_m > 0 ? close_looks : static_cast<std::uint32_t>(c.views.size() - 1);
      decision = AssessCandidate(c, params).decision;
      if (decision != FusionDecision::kNone) break;
    }
    const bool confirmed = decision == FusionDecision::kConfirm;
    const bool rejected = decision == FusionDecision::kReject;
    if (d.real) {
      (confirmed ? r.real_confirmed : rejected ? r.real_rejected : r.real_open) += 1;
    } else {
      (confirmed ? r.false_confirmed : rejected ? r.false_rejected : r.false_open) += 1;
    }
    r.same += (confirmed && d.confirmed) || (rejected && !d.confirmed) ? 1 : 0;
  }
  return r;
}

}  // namespace swarmbox::swarm::testing
