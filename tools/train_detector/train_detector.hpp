// Training of the victim detector (agent/swarm victim_detector*.hpp) on scenes the physics server's
// renderer draws (perception_scenes.hpp), as a reproducible build step:
//
//   cmake --build build --target train-detector
//     -> agent/swarm/models/victim_detector.yml.gz (the model, cv::FileStorage)
//        agent/swarm/models/victim_detector.json   (seeds, sample counts, training figures)
//
// Steps, all seeded (the same sources and seeds give the same model):
//   1. render the training scene sets (kTrainingSeeds) and the calibration sets
//      (kCalibrationSeeds): never one of perception_scenes::kEvaluationSeeds; half of the frames
//      get painted clutter (tarps, cones, rocks, specks of any colour, away from the people);
//   2. first stage: windows centred on every person at least half visible (and 4 one-cell shifts)
//      against random ground windows at least 1.5 m from any person; a ridge-regression linear
//      discriminant on standardised features; threshold at the 0.5th percentile of the centred
//      positives' scores;
//   3. second stage: the first stage's positive windows, and on the training scenes the first
//      stage's local maxima (the best 96 per frame, any score) within 0.75 m of a person as
//      positives, those at least 1.5 m from every person as negatives (hard negatives: what the
//      linear stage likes most); a cv::ml::RTrees forest;
//   4. calibration: the whole detector on the calibration scenes, detections labelled by the
//      ground truth, Platt's sigmoid fitted to the vote fractions (Platt 1999, with his target
//      smoothing);
//   5. figures on the calibration scenes: precision and recall at confidence 0.5.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "perception_scenes.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/swarm/victim_detector.hpp"
#include "swarmbox/swarm/victim_detector_model.hpp"

namespace swarmbox::train_detector {

struct TrainingOptions {
  std::vector<std::uint64_t> training_seeds;     // one scene set each
  std::vector<std::uint64_t> calibration_seeds;
  int scenes_per_set = 60;
  int forest_trees = 60;
  int forest_depth = 14;
  int max_negatives = 24000;  // second-stage negatives kept (a seeded sample)
  double ridge_lambda = 1e-2;
  // The stage-1 threshold: this percentile of the centred positives' scores [%].
  double stage1_percentile = 0.5;
  // Weigh the forest's classes equally (cv::ml priors inverse to the class counts).
  bool balance_classes = false;
  // Rounds of hard negatives: the forest's false candidates on the training frames (votes >= 0.2)
  // join the negatives (at most max_hard_negatives per round) and the forest is trained again.
  int hard_negative_rounds = 0;
  int max_hard_negatives = 20000;
  // The second stage also sees each candidate's blob features (swarm/blob_features.hpp: size,
  // shape, parts, edge orientations, model format 2); false (the forest recipe shipped until 2026-11-27)
  // trains the format-1 layout (window features and score).
  bool blob_features = false;
  // Extra training sets (seeds kNegativesSeedBase + 1..N) of the cones-and-rubble mix
  // (perception_scenes::DistractorMix::kConesRubble, 4 cones per person): more of the blob model's
  // false alarms among the second stage's negatives (the shipped recipe: 4). 0: none.
  int negatives_sets = 0;
  // Extra training sets (seeds kWorldsSeedBase + 1..N) on the mission's generated rubble fields
  // (perception_scenes::SarRubbleSpec, views at 15-45 m): the rubble ground, slabs, cover and
  // distractors the mission meets, where the detector trained on the mixed terrains alone gave
  // half the people no detection at all (`swarmbox-bench perception --only world:1`). 0: none.
  int world_sets = 0;
  // Distractors in each generated field of the world sets (sar_rubble.yaml's 25 unless set): more
  // tarps, cones, backpacks, debris and rocks among the same 4 people.
  int world_distractors = 25;
  // Rounds of stage 1's bootstrapping (train_detector.cpp AddStage1HardNegatives: each adds the
  // fitted stage's best windows away from every person, 16 a scene, to its negatives and fits it
  // again). 0: random negatives only (the recipes until 2026-11-28). Not with blob_features.
  int stage1_rounds = 0;
  // The first stage's cap on candidates per frame while calibrating and mining hard negatives (the
  // detector's default, VictimDetectorParams::max_candidates, unless set: a blob model is run at 96).
  int max_candidates = swarm::VictimDetectorParams{}.max_candidates;
  // The operating point: when not 0, the sigmoid is moved along the votes so that probability 0.5
  // falls at the lowest vote fraction where the calibration detections reach this precision (a
  // threshold chosen on calibration frames only, never on an evaluation seed); 0: Platt's fit as is.
  double operating_precision = 0;
  // The calibration frames' altitude band [m]: centre +- kCalibrationAltitudeBandM, the search
  // altitude, so that the sigmoid is fitted where the detector is used; 0: the training sets'
  // mixed altitudes (8-65 m, the forest recipes').
  double calibration_altitude_m = 0;
  // When > 0: a second sigmoid, fitted on the calibration seeds rendered again at this altitude
  // +- kCalibrationAltitudeBandM, for frames finer than the geometric mean of the two sets'
  // median scales (swarm::VictimDetectorModel::close_px_per_m): the mission's close looks from
  // 18 m. Needs calibration_altitude_m at least 2 bands above it.
  double close_calibration_altitude_m = 0;
  // The calibration frames as the renderer draws them, without the painted clutter the training
  // frames get (half of them): the sigmoid is then fitted on the world the detector meets, not on
  // the augmentation (the shipped recipe); false: half the calibration frames painted too (the
  // forest recipes').
  bool clean_calibration = false;
  // When not empty: the second stage's samples (candidates labelled as for the forest, and each
  // must-detect person's own centre as a positive) and the calibration frames' candidates are
  // written to this file as CNN patches (WritePatchFile format below).
  std::string export_patches;
  // When not empty: the second stage is a CNN trained by this script (train_cnn.py) on the exported
  // patches (export_patches, or a file beside cnn_onnx_out), run as `python SCRIPT --patches F
  // --out ONNX --seed cnn_seed --epochs cnn_epochs`; its ONNX goes into the model (format 3) and
  // the sigmoid is fitted on its logits. Empty: the forest (the shipped
  // model has a CNN: train-detector passes --cnn).
  std::string cnn_script;
  std::string python = "python3";  // the interpreter with torch (Debian: /usr/bin/python3)
  std::string cnn_onnx_out;        // where the script writes the ONNX (default: beside the patches)
  int cnn_epochs = 12;
  int cnn_seed = 1;
  // The network's three blocks' channels (train_cnn.py --widths) and the negatives each epoch
  // draws (--negatives-per-epoch). 24,48,96 over 16,32,64: on the generated rubble fields at 30 m
  // (bench case=world, seed 1, 96 candidates) AP 0.84 against 0.79 with the same patches and
  // epochs, at 2.25 times the network's cost (BENCHMARKS.md "Perception: spread candidates and a wider CNN").
  std::string cnn_widths = "24,48,96";
  int cnn_negatives_per_epoch = 48000;
  // The share of each epoch's negatives drawn from the hardest the network scores (train_cnn.py
  // --hard-fraction: mined at epochs 4, 7, 10). 0.5 over 0: on the rubble fields at 30 m (bench
  // case=world, the same patches) recall at precision 0.9 0.72 / 0.62 against 0.68 / 0.54 (seeds 1
  // / 20261121; BENCHMARKS.md "Perception: hard negatives for the CNN").
  double cnn_hard_fraction = 0.5;
  // The CNN's patch side [px] over 3 m (swarm::ValidCnnPatchPx): 32 (10.7 px/m, the shipped
  // model's); a model of low views 48 (16 px/m; BENCHMARKS.md "Perception: the close look":
  // tried on views from 10-20 m, not shipped).
  int cnn_patch_px = swarm::kCnnPatchPx;
  // The symmetries of each patch the CNN scores, logits averaged (swarm::VictimDetectorModel::
  // cnn_symmetries: 1, 4 or 8), set before the sigmoid is fitted; 0: 1 when training, the model's
  // own with --recalibrate.
  int cnn_symmetries = 0;
  // When both > 0: every training set's views between these heights [m] (the defaults: 8-65 m for
  // the mixed terrains, 15-45 m for the rubble fields); e.g. 10-20 m for a model of close looks.
  double view_min_altitude_m = 0;
  double view_max_altitude_m = 0;
  // Recalibrate() only: when not empty, this ONNX (train_cnn.py's, e.g. run again on a model's
  // exported patches with other settings) replaces the model's CNN before the sigmoid is refitted.
  std::string replace_cnn;
  // Recalibrate() only: when not empty, this ONNX becomes the model's close-look CNN
  // (VictimDetectorModel::close_cnn_onnx: train_cnn.py's, on patches of close_cnn_patch_px from
  // views near the close altitude, e.g. the CNN of the train-close-detector target's model), and
  // the close sigmoid (close_calibration_altitude_m, which it needs) is fitted to its logits on the
  // model's own candidates. Without it a recalibration keeps the model's close CNN, if any, when
  // close_calibration_altitude_m is set (the close sigmoid refitted to it), and drops it otherwise.
  std::string close_cnn;
  int close_cnn_patch_px = 64;
};

// The patch file (--export-patches), little-endian:
//   header  8 bytes "SWBPATCH", uint32 version (1), uint32 patch_px, uint32 channels (3),
//           float32 px_per_m, uint64 count
//   records count times: int8 label (1 person, 0 no person), uint8 split (0 training,
//           1 calibration), then patch_px * patch_px * 3 uint8 (rows, columns, BGR)
// The patches are swarm::CandidatePatchSampler's (candidate_patch.hpp), what the detector's CNN sees.
inline constexpr char kPatchFileMagic[8] = {'S', 'W', 'B', 'P', 'A', 'T', 'C', 'H'};
inline constexpr std::uint32_t kPatchFileVersion = 1;
enum class PatchSplit : std::uint8_t { kTraining = 0, kCalibration = 1 };

// The cones-and-rubble sets' seeds start above this (disjoint from training, calibration and
// evaluation seeds).
inline constexpr std::uint64_t kNegativesSeedBase = 7'200'000;
// The generated rubble-field sets' seeds start above this.
inline constexpr std::uint64_t kWorldsSeedBase = 7'300'000;
// The training and calibration sets' seeds start above these.
inline constexpr std::uint64_t kTrainingSeedBase = 7'000'000;
inline constexpr std::uint64_t kCalibrationSeedBase = 7'100'000;
// The seeds of `sets` scene sets: base + 1 .. base + sets.
std::vector<std::uint64_t> SeedSets(std::uint64_t base, int sets);

// Half the width of the calibration altitude band [m].
inline constexpr double kCalibrationAltitudeBandM = 3.0;

// The options as the trainer's command line (recorded in the model and its JSON report).
std::string RecipeText(const TrainingOptions& options);

// The trainer's defaults (the forest recipe shipped until 2026-11-27): 8 training sets
// (7000001-7000008), 2 calibration sets. The shipped CNN's options: tools/train_detector/CMakeLists.txt.
TrainingOptions DefaultTrainingOptions();

// The scene mix of one training or calibration set: altitudes 8-65 m, noise 2-12 levels, 30 % of
// the people partly covered, 2 distractors per person, the varied look (perception_scenes.hpp)
// except for every seed divisible by 4 (the original hi-vis look).
perception_scenes::SceneSetParams TrainingSceneSet(std::uint64_t seed, int scenes);

// A cones-and-rubble set (TrainingOptions::negatives_sets): the training mix, every world in the
// varied look on rubble terrain, 4 traffic cones per person.
perception_scenes::SceneSetParams NegativesSceneSet(std::uint64_t seed, int scenes);

// A generated rubble-field set (TrainingOptions::world_sets): worlds as sar_rubble.yaml generates
// them, views at 15-45 m, 80 % of them near a person.
perception_scenes::SceneSetParams WorldSceneSet(std::uint64_t seed, int scenes, int distractors = 25);

// A calibration set: the training mix, at calibration_altitude_m +- kCalibrationAltitudeBandM when
// that is not 0.
perception_scenes::SceneSetParams CalibrationSceneSet(std::uint64_t seed, int scenes, double calibration_altitude_m);

struct TrainingReport {
  int training_scenes = 0;
  int calibration_scenes = 0;
  int stage1_positives = 0;
  int stage1_negatives = 0;
  int stage2_positives = 0;
  int stage2_negatives = 0;
  int stage2_hard_negatives = 0;
  double stage1_positive_recall = 0;  // share of centred positives at or above the threshold
  double stage1_calibration_recall = 0;  // must-detect people with a first-stage candidate
  int calibration_detections = 0;
  int calibration_persons = 0;   // at least half visible
  int calibration_tp = 0;        // at confidence >= 0.5
  int calibration_fp = 0;
  double precision = 0;
  double recall = 0;
  double seconds = 0;
};

// Renders, trains and calibrates. Fails when a seed is an evaluation seed or rendering fails.
Result<swarm::VictimDetectorModel> Train(const TrainingOptions& options, TrainingReport* report);

// Steps 4-5 again on a trained model (its first stage and forest kept): for a calibration fix
// without retraining. The model must name the same calibration seeds. The options are checked as
// Train checks them, before the model is read.
Result<swarm::VictimDetectorModel> Recalibrate(const TrainingOptions& options, const std::string& model_path,
                                               TrainingReport* report);

std::string ReportJson(const swarm::VictimDetectorModel& model, const TrainingOptions& options,
                       const TrainingReport& report,
                       const std::string& model_file = "victim_detector.yml.gz");

}  // namespace swarmbox::train_detector
