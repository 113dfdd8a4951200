// Thermal evidence for a detection: how much warmer than its surroundings the thermal camera
// (airframe `thermal:`, a FLIR Boson 320) saw the ground point the colour detector placed a person
// at, and the detector's confidence with it: a logistic calibration of both together, fitted on the
// shipped detector's own candidates in rendered training worlds (`swarmbox-fit-thermal`, the
// `fit-thermal` target; models/thermal_evidence.yaml).
//
//   ThermalView view{kelvin, k, pose};                     // one frame: CV_32F kelvin, its camera
//   std::optional<double> c = ThermalContrastAt(view, point_m, evidence.radius_m);
//   if (c) confidence = evidence.Fuse(confidence, *c);
//
// The contrast: the 98th percentile of the temperatures within radius_m of the point minus the
// median of the ring from 1.7 to 3.4 radius_m around it [K] (a person is a few warm pixels, the
// head warmest; the ring is the ground they lie on). The fusion: sigmoid(colour_weight x
// logit(confidence) + slope_per_k x c + bias), c clamped to [kMinContrastK, kMaxContrastK].
//
// With a thermal classifier (cnn_weight > 0: a small CNN trained on thermal patches of people and
// of the look-alikes the colour detector flags, train_thermal_cnn.py): the patch around the point
// (ThermalPatchAt: the frame resampled onto the ground, 8 cm a pixel, 3.2 m square) is scored by
// ThermalClassifier and the fusion adds cnn_weight x its logit. A person's shape in the thermal
// frame (a warm head, limbs, a body's length) is what a sun-warmed backpack or sheet of debris does
// not have, however warm it is.
// Pure: frames and points in.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/swarm/geolocation.hpp"

namespace swarmbox::swarm {

inline constexpr double kMinContrastK = -10.0;
inline constexpr double kMaxContrastK = 40.0;

// One thermal frame: the apparent temperature per pixel [K] (CV_32F), its intrinsics and the
// (estimated) optical pose it was taken from.
struct ThermalView {
  cv::Mat kelvin;
  PinholeIntrinsics k;
  OpticalPose pose;
};

// The contrast at world point `point_m` (see above); nullopt when the point is behind the camera
// or its ring leaves the frame, or the disc is under one pixel across.
std::optional<double> ThermalContrastAt(const ThermalView& view, const Eigen::Vector3d& point_m,
                                        double radius_m);

// The thermal classifier's input (ThermalPatchAt): kThermalPatchPx square, kThermalPatchM of ground
// a pixel, east right and north up; the temperatures minus the patch's median, over
// kThermalPatchScaleK, clamped to [kThermalPatchMin, kThermalPatchMax] (a CV_32F matrix).
inline constexpr int kThermalPatchPx = 40;
inline constexpr double kThermalPatchM = 0.08;
inline constexpr double kThermalPatchScaleK = 10.0;
inline constexpr float kThermalPatchMin = -2.0F, kThermalPatchMax = 4.0F;

// The patch around world point `point_m` (bilinear in the frame); false when any of it lies
// outside the frame or behind the camera.
bool ThermalPatchAt(const ThermalView& view, const Eigen::Vector3d& point_m, cv::Mat* patch);

// A CNN on thermal patches (ONNX, opset 11, N x 1 x kThermalPatchPx x kThermalPatchPx in, N x 1
// logits out, > 0 for "person"), run by cv::dnn: Logit is the mean of its logits over the eight
// symmetries of the square (people lie at any heading). Not thread-safe (one per perception).
class ThermalClassifier {
 public:
  // kInvalidArgument when OpenCV cannot read the network or its output is not one logit a patch.
  static Result<std::unique_ptr<ThermalClassifier>> FromOnnx(std::string_view onnx);
  double Logit(const cv::Mat& patch);

 private:
  ThermalClassifier() = default;
  cv::dnn::Net net_;
  std::vector<cv::Mat> views_;
  cv::Mat input_;
};

struct ThermalEvidence {
  double colour_weight = 1.0;  // on the colour detector's logit
  double slope_per_k = 0.0;    // on the contrast [1/K]
  double bias = 0.0;
  double radius_m = 0.7;  // the disc ThermalContrastAt looks in [m]
  double cnn_weight = 0.0;  // on the thermal classifier's logit (0: no classifier)
  std::string cnn_model;    // its file's name (beside the yaml)
  // The classifier's ONNX (cnn_weight > 0; ShippedThermalEvidence: models/thermal_cnn.onnx).
  std::shared_ptr<const std::string> cnn_onnx;
  // The confidence with the contrast and the classifier's logit (clamped to +-kMaxCnnLogit); the
  // defaults leave it as it was.
  double Fuse(double confidence, double contrast_k, double cnn_logit = 0.0) const;
};
inline constexpr double kMaxCnnLogit = 20.0;

// The evidence applied to a candidate: its confidence with the contrast at its ground point and,
// with a classifier, the classifier's logit on its patch (0 when the patch leaves the frame); a
// point the frame does not see (no contrast) keeps its confidence. What VictimPerception and the
// perception bench do to each candidate. One per thread (the classifier is not thread-safe).
class ThermalFusion {
 public:
  // Aborts when the evidence's classifier does not load (the shipped one is tested to).
  explicit ThermalFusion(const ThermalEvidence& evidence);
  double Apply(double confidence, const ThermalView& view, const Eigen::Vector3d& point_m);

 private:
  ThermalEvidence evidence_;
  std::unique_ptr<ThermalClassifier> classifier_;
  cv::Mat patch_;
};

// The `thermal_evidence:` mapping of a models/thermal_evidence.yaml ({colour_weight, slope_per_k,
// bias, radius_m, optional cnn_weight and cnn_model (the ONNX file's name, beside the yaml), and
// the fit's provenance, which is read past}). kInvalidArgument: missing or out-of-range figures.
// cnn_onnx is left empty: the caller loads the file cnn_model names.
Result<ThermalEvidence> ParseThermalEvidence(const yaml::Node& root);
// The fit that ships: agent/swarm/models/thermal_evidence.yaml, compiled in.
const ThermalEvidence& ShippedThermalEvidence();

}  // namespace swarmbox::swarm
