// VictimDetectorModel: the trained part of the victim detector (victim_detector.hpp), its features
// and its file format. Written by `tools/train_detector` (target `train-detector`), shipped as
// agent/swarm/models/victim_detector.yml.gz and compiled into the agent (ShippedDetectorModel()).
//
// Features (aggregated channel features, Dollar et al., "Fast Feature Pyramids for Object
// Detection", PAMI 2014), computed on the frame rescaled to kCanonicalPxPerM (so a person is the
// same size in pixels at every altitude) and padded by kPadCells on every side:
//   channels  L, u, v (CIE Luv, 8-bit scaled to [0, 1]), gradient magnitude of L, and the magnitude
//             in kOrientations unsigned orientation bins: kChannels maps;
//   cells     each channel averaged over kShrink x kShrink pixels (a cell is 0.25 m);
//   window    kWindowCells x kWindowCells cells (3 x 3 m, a lying adult with room around it).
// A window's feature vector: the gradient cells as they are, the colour cells minus the window's
// mean of that channel (a person differs from the ground around it, whatever the light), and the
// window's three colour means: kFeatures values.
//
// Classifier: a linear first stage (ridge-regression discriminant, weights per channel cell,
// evaluated densely as one correlation per channel), then cv::ml::RTrees (a random forest) on the
// first stage's local maxima with the first-stage score as one more feature and, in models of
// format 2 with blob_features = kBlobFeatures, the candidate's blob features (blob_features.hpp:
// size, shape, parts and edge orientations, independent of the person's heading), and a Platt
// sigmoid that maps the forest's vote fraction to a probability (fitted on calibration scenes).
// Format 1 models (window features and score only) still load and run. A format-3 model carries a
// small convolutional network instead of the forest (cnn_onnx: ONNX bytes, run with cv::dnn on each
// candidate's colour patch, candidate_patch.hpp; trained by tools/train_detector/train_cnn.py), its
// logit mapped to a probability by the Platt sigmoid.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/ml.hpp>

#include "swarmbox/common/result.hpp"
#include "swarmbox/swarm/candidate_patch.hpp"

namespace swarmbox::swarm {

inline constexpr double kCanonicalPxPerM = 8.0;
inline constexpr int kShrink = 2;
inline constexpr int kWindowCells = 12;
inline constexpr int kPadCells = 4;           // 1 m: people cut by the border are still seen
inline constexpr int kOrientations = 4;
inline constexpr int kColourChannels = 3;
inline constexpr int kChannels = kColourChannels + 1 + kOrientations;
inline constexpr int kWindowFeatures = kChannels * kWindowCells * kWindowCells + kColourChannels;
inline constexpr int kForestFeatures = kWindowFeatures + 1;  // + the first-stage score
// The CNN's input normalisation (pixel - mean) * scale, the same in train_cnn.py.
inline constexpr double kCnnInputMean = 127.5;
inline constexpr double kCnnInputScale = 1.0 / 64.0;
// (then the blob features when the model has them: VictimDetectorModel::forest_inputs())

// Channel maps at cell resolution (CV_32F each), with scratch images kept between frames.
struct ChannelMaps {
  std::vector<cv::Mat> cells;  // kChannels maps, rows x cols cells
  cv::Mat canonical, padded, luv, l, gx, gy, mag, angle;
  std::vector<cv::Mat> full;   // kChannels maps at canonical pixel resolution
  int rows() const { return cells.empty() ? 0 : cells[0].rows; }
  int cols() const { return cells.empty() ? 0 : cells[0].cols; }
};

// Rescales `bgr` (CV_8UC3) by `scale` (canonical px per input px), pads and computes the maps.
void ComputeChannels(const cv::Mat& bgr, double scale, ChannelMaps* maps);

// The window with top-left cell (row, col): kWindowFeatures values appended to `out`.
void WindowFeatures(const ChannelMaps& maps, int row, int col, float* out);

// Canonical-pixel position (padded image) of a window's centre, and back to an input pixel.
inline double WindowCentreCanonical(int cell) { return kShrink * (cell + kWindowCells / 2.0); }
inline double CanonicalToInput(double padded_canonical_px, double scale) {
  return (padded_canonical_px - kPadCells * kShrink) / scale - 0.5;
}
inline double InputToCanonical(double input_px, double scale) {
  return (input_px + 0.5) * scale + kPadCells * kShrink;
}

inline bool ValidCnnSymmetries(int n) { return n == 1 || n == 4 || n == 8; }

struct VictimDetectorModel {
  // First stage: score(window) = bias + sum over channels of the correlation of the cell map with
  // kernels[c] (kWindowCells x kWindowCells, CV_32F); candidates score >= stage1_threshold.
  std::vector<cv::Mat> kernels;
  double bias = 0;
  double stage1_threshold = 0;
  cv::Ptr<cv::ml::RTrees> forest;  // class 1 = person; forest_inputs() inputs (empty with a CNN)
  // The convolutional second stage (format 3), when not empty: an ONNX network from a batch of
  // kCnnPatchPx x kCnnPatchPx BGR patches (N x 3 x H x W, (pixel - kCnnInputMean) * kCnnInputScale)
  // to one logit per patch (> 0: person). It replaces the forest; the sigmoid then maps the logit.
  std::vector<std::uint8_t> cnn_onnx;
  // Its patches' side [px] over kCnnPatchM (ValidCnnPatchPx; the trainer's --cnn-patch-px): the
  // shipped model's 48 (16 px/m, the camera's resolution at the 30 m search altitude); kCnnPatchPx
  // (10.7 px/m) in a file without the field.
  int cnn_patch_px = kCnnPatchPx;
  // Of the square's 8 symmetries (turns by 90 degrees, mirrored), how many of each patch the CNN
  // scores, its logits averaged (test-time augmentation; ValidCnnSymmetries: 1, 4 or 8). The
  // network was trained on all 8 (train_cnn.py: people lie at any heading), so each is a fair view
  // and the mean is less noisy than one; the sigmoid is fitted to the mean (the trainer's
  // --cnn-symmetries). 1: the network once, as before the field existed (files without it).
  int cnn_symmetries = 1;
  int blob_features = 0;           // 0 (format 1) or kBlobFeatures, after the kForestFeatures
  double platt_a = -8.0;           // p = 1 / (1 + exp(platt_a * votes + platt_b))
  double platt_b = 4.0;
  // A second sigmoid for frames at least close_px_per_m fine on the ground (0: none, one sigmoid
  // for every frame): the mission's close looks (revisits from 18 m) see a candidate at another
  // scale, against other pixels, and the network's scores there mean other odds than at the
  // search altitude the first sigmoid was fitted at (the trainer's --close-calibration-altitude;
  // optional in the file).
  double close_px_per_m = 0;
  double close_platt_a = 0;
  double close_platt_b = 0;
  // A second CNN for those frames (optional, with close_px_per_m > 0; empty, as in the shipped
  // model: the CNN above scores them too), on patches of close_cnn_patch_px over kCnnPatchM, the
  // close sigmoid fitted to its logits. The one tried (tools/train_detector README, "A CNN for the
  // close look"; not shipped): trained on views from 15-21 m, 64 px (21.3 px/m, where the search
  // CNN's 48 keep 16 of the camera's 25.8 px/m at 18 m).
  std::vector<std::uint8_t> close_cnn_onnx;
  int close_cnn_patch_px = 0;
  std::vector<std::uint64_t> training_seeds;     // scene-set seeds the forest was trained on
  std::vector<std::uint64_t> calibration_seeds;  // scene-set seeds the sigmoid was fitted on
  std::string recipe;  // the trainer's options, as its command line (the model's provenance)

  int forest_inputs() const { return kForestFeatures + blob_features; }
  bool has_cnn() const { return !cnn_onnx.empty(); }
  bool has_close_cnn() const { return !close_cnn_onnx.empty(); }
  // The model as the close frames see it: the same first stage, the close CNN and its patches, the
  // close sigmoid as its only one (what VictimDetector runs on frames at least close_px_per_m fine,
  // and what the trainer fits the close sigmoid on).
  VictimDetectorModel CloseView() const;

  // The forest flattened for prediction without allocation (FlattenForest(); the same decisions
  // as cv::ml::DTrees::predict for ordered variables: value <= threshold goes left, unless the split
  // is inversed).
  struct ForestNode {
    int var = -1;          // -1: a leaf
    float threshold = 0;
    int left = -1;         // indices into nodes
    int right = -1;
    float person = 0;      // leaf: 1 when it votes "person"
  };
  std::vector<ForestNode> nodes;
  std::vector<int> roots;

  // Rebuilds nodes/roots from `forest`.
  void FlattenForest();
  // Fraction of the trees voting "person" for forest_inputs() values.
  double Votes(const float* forest_features) const;
  // First-stage score of one feature vector (the same sum as the dense correlation).
  double LinearScore(const float* window_features) const;
  // Linear weights over kWindowFeatures in feature order (for training: folded into kernels).
  void SetLinear(const std::vector<double>& weights, double bias);
  double Probability(double votes) const;
  // The same for a detection on a frame of `pixels_per_m`: the close sigmoid when the model has one
  // and the frame is at least close_px_per_m fine.
  double Probability(double votes, double pixels_per_m) const;
};

Status SaveDetectorModel(const VictimDetectorModel& model, const std::string& path);
Result<std::shared_ptr<const VictimDetectorModel>> LoadDetectorModel(const std::string& path);
// From the text of the YAML file (the shipped model is compiled in gzip-compressed).
Result<std::shared_ptr<const VictimDetectorModel>> LoadDetectorModelFromText(const std::string& yaml);
Result<std::string> GunzipText(const unsigned char* data, std::size_t size);

// The model compiled into the binary from agent/swarm/models/victim_detector.yml.gz. Loaded once;
// aborts (SWARMBOX_CHECK) when the compiled-in bytes do not parse: a broken build, not a runtime
// condition.
std::shared_ptr<const VictimDetectorModel> ShippedDetectorModel();

}  // namespace swarmbox::swarm
