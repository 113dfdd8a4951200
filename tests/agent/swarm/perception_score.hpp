// Scoring of the perception pipeline on the seeded scenes of tools/train_detector/
// perception_scenes.hpp (rendered by the physics server's camera), used by the perception tests and
// `swarmbox-bench perception`.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "perception_scenes.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/raft/mission_state.hpp"
#include "swarmbox/swarm/sighting_fusion.hpp"
#include "swarmbox/swarm/victim_perception.hpp"

namespace swarmbox::swarm::testing {

using perception_scenes::RenderScenes;
using perception_scenes::RenderTiltedScenes;
using perception_scenes::Scene;
using perception_scenes::SarRubbleSpec;
using perception_scenes::SceneSetParams;
using perception_scenes::SceneVictim;
using perception_scenes::Visibility;

struct PerceptionScore {
  int scenes = 0;
  int full_victims = 0;        // must-detect instances
  int true_positives = 0;      // detections matched to a kFull victim (one per victim)
  int false_positives = 0;     // detections matching no victim in view
  int partial_detected = 0;    // detections matched to a kPartial victim (not scored)
  int partial_victims = 0;
  std::vector<double> errors_m;  // geolocation error of each true positive [m]
  double precision() const;
  double recall() const;
  double median_error_m() const;
  double p90_error_m() const;
};

// Runs the pipeline on every scene with the camera pose `perturb`ed (seeded: position 1-sigma
// position_sigma_m per axis, attitude 1-sigma attitude_sigma_rad per axis; zero = true pose) and
// scores it: a detection matches the nearest victim within match_radius_m (victims lie >= 6 m
// apart, so 2.5 m cannot match the wrong one; MissionState merges sightings within 5 m).
struct PoseNoise {
  std::uint64_t seed = 7;
  double position_sigma_m = 0.0;
  double attitude_sigma_rad = 0.0;
};
PerceptionScore ScorePerception(const std::vector<Scene>& scenes, const PerceptionParams& params,
                                const PoseNoise& pose_noise, double match_radius_m = 2.5);

// Detection curves of the detector alone (no latency queue): every detection of every scene with
// its confidence, geolocated with the true pose; a detection within match_radius_m of a person at
// least must_fraction visible is a true positive (the first one; a second is a false positive),
// one near a less visible person is not counted, any other is a false positive.
struct DetectionCurve {
  int scenes = 0;
  int persons = 0;                 // at least must_fraction visible
  int tp = 0;                      // at confidence >= operating_point
  int fp = 0;
  double precision = 1.0;          // at the operating point
  double recall = 1.0;
  double ap = 0.0;                 // area under the interpolated precision-recall curve (VOC)
  // Two more points of the curve, at any confidence: the highest recall at which the precision is
  // still at least 0.9 (0 when it never is), and the recall of all the detections (the first
  // stage's and the detector's floor together).
  double recall_at_precision_90 = 0.0;
  double max_recall = 0.0;
  double ms_per_frame = 0.0;       // Detect() wall time per frame (the caller sets the threads)
};
// Called for each person at least must_fraction visible that no detection at or above the
// operating point matched: its scene and the highest confidence of a detection within
// match_radius_m of it (0 when none).
using MissFn = std::function<void(const Scene& scene, const SceneVictim& person, double best_confidence)>;
// With `thermal`, a scene's thermal frame (Scene::thermal; scenes without one are scored on colour
// alone) moves each detection's confidence by the thermal evidence at its ground point, as the
// agent's VictimPerception does, and the detections are ranked again.
DetectionCurve ScoreDetections(const std::vector<Scene>& scenes, VictimDetector& detector,
                               double operating_point = 0.5, double must_fraction = 0.5,
                               double match_radius_m = 1.5, const MissFn& on_miss = {},
                               const ThermalEvidence* thermal = nullptr);

// A trial's decided candidates as the leader logged them (event=confirmed / event=rejected carry
// every view: sighting_fusion.hpp AddEvidence's drones, confidences, 0 for a miss, viewers
// "x:y:height" and view_t), rebuilt as raft::Candidates (each view's ground point is the
// candidate's, which the fusion does not read); a candidate decided twice (a later leader) comes
// once, with its last record. `real`: within real_radius_m of a victim of the world.
struct DecidedCandidate {
  raft::Candidate candidate;
  bool real = false;
  bool confirmed = false;  // the logged decision
};
// `log_lines`: every log line of the trial (others are skipped); `victims`: the world's (x, y).
std::vector<DecidedCandidate> DecidedCandidates(const std::vector<LogfmtFields>& log_lines,
                                                const std::vector<Eigen::Vector2d>& victims,
                                                double real_radius_m);

// The revisits' close looks as the mission's fusion met them (`swarmbox-bench perception --looks
// RUN`), per look rather than per frame (a look's ~4 frames of one hover are nearly one image): a
// close look is a view from at most close_height_m up. close_recall() and close_false_repeat() are
// the figures FusionParams' close_recall and close_false_repeat stand for. The sample follows the
// mission's policy (a person's candidate is looked at again until it is decided), so it is the
// looks the fusion meets, not a uniform sample of the detector.
struct CloseLookTally {
  static constexpr std::size_t kBins = 5;  // detections by confidence: [0.5, 0.6) ... [0.9, 1]
  int real_candidates = 0;
  int false_candidates = 0;
  int real_looks = 0;
  int real_detected = 0;
  int false_looks = 0;
  int false_detected = 0;
  std::array<int, kBins> real_bins{};
  std::array<int, kBins> false_bins{};
  void Add(const CloseLookTally& other);
  double close_recall() const { return real_looks ? static_cast<double>(real_detected) / real_looks : 0.0; }
  double close_false_repeat() const {
    return false_looks ? static_cast<double>(false_detected) / false_looks : 0.0;
  }
};
CloseLookTally TallyCloseLooks(const std::vector<DecidedCandidate>& decided, double close_height_m);

// The same candidates decided again by `params` on their own records: the views in order, the
// candidate assessed after each (AssessCandidate; revisits done = the close looks so far, or the
// views after the first without close looks), the first decision taken; `open` when the record
// ended undecided (the mission would have looked again: what that look sees is not in the logs).
// With the params the mission ran, `same` counts the candidates decided as logged.
struct Redecision {
  int real_confirmed = 0, real_rejected = 0, real_open = 0;
  int false_confirmed = 0, false_rejected = 0, false_open = 0;
  int same = 0;
  void Add(const Redecision& other);
};
Redecision Redecide(const std::vector<DecidedCandidate>& decided, const FusionParams& params);

}  // namespace swarmbox::swarm::testing
