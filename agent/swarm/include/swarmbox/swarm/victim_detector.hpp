// VictimDetector: finds people on the ground in a downward camera frame (8-bit BGR) with a trained
// sliding-window detector (the model: victim_detector_model.hpp, trained by tools/train_detector
// on frames the physics server's renderer draws from seeds disjoint from the evaluation seeds).
//
//   VictimDetector det;                        // the shipped model; reuse one per camera
//   det.Detect(bgr, fx_px / height_above_ground_m, &blobs);
//
// Per frame:
//   1. scale: the frame is resized so the ground is kCanonicalPxPerM (8 px/m) at the image centre
//      (the expected person size from the altitude: one pyramid level per frame, chosen by the
//      altitude, instead of searching every scale), padded by 1 m so people cut by the border are
//      still windows;
//   2. features: aggregated channel features (Luv, gradient magnitude, 4 orientations, 0.25 m
//      cells), windows of 3 x 3 m at a stride of one cell;
//   3. first stage: a linear score for every window (one correlation per channel), its local
//      maxima (the best within candidate_spacing_m) above the trained threshold, at most
//      max_candidates of them;
//   4. second stage: with a model that carries a CNN (format 3, the shipped model), the network on
//      every candidate's colour patch (candidate_patch.hpp; all of a frame's candidates in one
//      batch, one cv::dnn forward), its logit mapped to a probability by the trained Platt
//      sigmoid: the confidence, in [0, 1]; with a forest model (formats 1 and 2), a random forest
//      (cv::ml::RTrees) on each candidate (its window features, its first-stage score and, when the
//      model has them, its blob features: blob_features.hpp), its vote fraction mapped the same way;
//   5. non-maximum suppression: of candidates closer than nms_radius_m, the most confident stays.
// A detection whose person box (centre +- 1 m) leaves the image is a partial view, its confidence
// capped at partial_confidence_cap (it cannot confirm a victim alone: MissionState needs 0.9).
// Detections under min_confidence are not reported.
//
// A model with a close-look CNN (VictimDetectorModel::close_cnn_onnx; tried, not the shipped model:
// tools/train_detector README "A CNN for the close look"): frames at least close_px_per_m fine on
// the ground (the mission's close looks from 18 m: 25.8 px/m; the switch is 20 px/m, 23 m for the
// x500's camera) get the same first stage, then that CNN on its own patches (64 px over 3 m in the
// one tried) and the close sigmoid (model.CloseView(), run by a second detector).
//
// Cost with the shipped CNN (24, 48, 96 channels, up to 96 candidates): ~13 ms per 640 x 360 frame
// at 10 m, ~31 ms at 30 m, ~48 ms at 60 m on one core (BENCHMARKS.md "Perception: spread candidates
// and a wider CNN"; the scale of step 1 makes low altitudes cheaper and high ones dearer: at 60 m
// the frame is enlarged to keep 8 px/m); a forest model ~4-14 ms. Scratch images are kept between
// frames; OpenCV's filters and cv::dnn still allocate internal buffers per frame
// (allocation_test.cpp). Frames come at up to 5 Hz, outside the control loop. A forest model with
// blob features adds them per candidate (0.25 ms of CPU each measured at load ~9: BENCHMARKS.md
// "Blob features for the second stage").
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include "swarmbox/swarm/blob_features.hpp"
#include "swarmbox/swarm/candidate_patch.hpp"
#include "swarmbox/swarm/geolocation.hpp"
#include "swarmbox/swarm/victim_detector_model.hpp"

namespace swarmbox::swarm {

struct VictimDetectorParams {
  double person_area_m2 = 0.59;       // plan-view area of a lying person [m^2] (expected_area_px)
  // First-stage maxima passed to the second stage, best first. 96: on the generated rubble fields
  // at 30 m (bench case=world, seeds 1 and 20261121) 48 leave a third of the people without a
  // candidate (max_recall 0.67 and 0.66 with the CNN of 2026-11-28); 96 cost the second stage twice
  // (BENCHMARKS.md "Perception: spread candidates and a wider CNN").
  int max_candidates = 96;
  // A first-stage candidate is the highest score within +- this on the ground (rounded to whole
  // 0.25 m cells, at least one). 0.5 m: with one cell, a rubble field's clutter takes several
  // candidates per block and the people go without; at 1 m a person 1 m from a tarp is suppressed
  // by it (bench, seed 1, 96 candidates, the wider CNN: AP world 0.76 / 0.85 / 0.84 at 0.25 / 0.5 /
  // 1 m, mixed scenes at 30 m 0.85 / 0.81 / 0.77). The trainer mines its patches with the same.
  double candidate_spacing_m = 0.5;
  // Detections closer than this on the ground are one. 1.5 m: the training labels a candidate
  // within 0.75 m of a person "person" and one 1.5 m or more from every person "none", so a
  // candidate in between (the other end of a lying person: 1.7 m long) is never taught either
  // way and can score high beside the person's own detection (a CNN did: a second detection
  // 1.1 m from one person at 10 m); the bench matches detections to people within 1.5 m.
  double nms_radius_m = 1.5;
  double min_confidence = 0.05;       // detections below are dropped
  double partial_half_extent_m = 1.0; // a detection this close to the border is a partial view
  double partial_confidence_cap = 0.8;
};

struct ImageBlob {
  Eigen::Vector2d centroid_px = Eigen::Vector2d::Zero();  // window centre (u right, v down)
  double area_px = 0;            // the person's expected plan area at this scale [px^2]
  double expected_area_px = 0;   // the same (kept for geolocation's consumers)
  bool partial = false;          // the person box leaves the image
  double linear_score = 0;       // first-stage score (margin of the linear stage)
  double votes = 0;              // second-stage score: the forest's vote fraction for "person"
                                 // [0, 1], or the CNN's logit (has_cnn())
  double confidence = 0;         // calibrated probability [0, 1] (capped for partial views)
};

class VictimDetector {
 public:
  // The model compiled into the binary (ShippedDetectorModel()).
  explicit VictimDetector(const VictimDetectorParams& params = {});
  VictimDetector(std::shared_ptr<const VictimDetectorModel> model, const VictimDetectorParams& params);

  // bgr: CV_8UC3. pixels_per_m: image scale on the ground at the image centre [px/m]
  // (fx_px / height above ground for a nadir camera), > 0. `out` is cleared first.
  void Detect(const cv::Mat& bgr, double pixels_per_m, std::vector<ImageBlob>* out);
  // Same, with the scale from the camera pose: fx over the range along the optical axis to the
  // ground (tilted cameras), and no detection where a pixel's ray misses the ground.
  void Detect(const cv::Mat& bgr, const PinholeIntrinsics& k, const OpticalPose& pose,
              double ground_z_m, std::vector<ImageBlob>* out);

  const VictimDetectorParams& params() const { return params_; }
  const VictimDetectorModel& model() const { return *model_; }
  // The close-look CNN's detector (null: the model has none; model().CloseView()).
  const VictimDetector* close() const { return close_.get(); }
  const ChannelMaps& channels() const { return maps_; }  // of the last frame (training, debugging)

  // Steps 1-3 on their own (training mines the forest's samples from these): the first-stage
  // candidates of `bgr` at `pixels_per_m`, as (row, col, score) of the window's top-left cell,
  // best first. Uses the model's kernels and threshold; fills channels() and, when the model has
  // blob features, gives the frame to the blob feature extractor (ForestFeatures()).
  struct Candidate {
    int row = 0;
    int col = 0;
    double score = 0;
    double sub_row = 0;  // peak position refined to a fraction of a cell
    double sub_col = 0;
  };
  const std::vector<Candidate>& Candidates(const cv::Mat& bgr, double pixels_per_m, int max_candidates,
                                           double threshold);
  // The forest's model().forest_inputs() values for candidate `c` of the last Candidates() call
  // (the same frame and scale): what the second stage sees.
  void ForestFeatures(const Candidate& c, float* out);
  // A candidate's window centre in pixels of the frame of the last Candidates() call.
  Eigen::Vector2d CentrePx(const Candidate& c) const;
  // The CNN's input patch of candidate `c` of the last Candidates() call (CandidatePatchSampler
  // on that frame, which must still be alive, at CentrePx(c)): what a convolutional second stage
  // sees, whatever the model's second stage.
  void CnnPatch(const Candidate& c, cv::Mat* patch);

 private:
  // The second stage's score (votes or logit) of each cands[kept_[i]] into scores_[i].
  void SecondStageScores(const std::vector<Candidate>& cands);
  // The CNN's logits for the candidates cands[kept[i]] into scores[i] (one batched forward).
  void CnnScores(const std::vector<Candidate>& cands, const std::vector<int>& kept, std::vector<double>* scores);
  template <typename KeepFn>
  void DetectImpl(const cv::Mat& bgr, double pixels_per_m, KeepFn keep, std::vector<ImageBlob>* out);

  std::shared_ptr<const VictimDetectorModel> model_;
  std::unique_ptr<VictimDetector> close_;  // on model_->CloseView(), for close frames (Detect only)
  VictimDetectorParams params_;
  ChannelMaps maps_;
  BlobFeatureExtractor blob_;
  CandidatePatchSampler patches_;
  cv::Mat frame_;              // the last Candidates() frame (a header, not a copy) and its scale
  double frame_px_per_m_ = 0;
  bool patch_frame_set_ = false;
  cv::dnn::Net cnn_;           // from model().cnn_onnx, when it has one
  std::vector<cv::Mat> patch_batch_;
  cv::Mat cnn_input_, cnn_output_;
  std::vector<int> kept_;
  std::vector<double> scores_;
  double scale_ = 1;  // canonical pixels per frame pixel, of the last Candidates() call
  cv::Mat score_, filtered_, dilated_;
  std::vector<float> samples_;
  std::vector<Candidate> candidates_;
  std::vector<ImageBlob> scratch_;
};

}  // namespace swarmbox::swarm
