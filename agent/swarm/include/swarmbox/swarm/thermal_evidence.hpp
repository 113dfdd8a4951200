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
// Pure: frames and points in.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

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

struct ThermalEvidence {
  double colour_weight = 1.0;  // on the colour detector's logit
  double slope_per_k = 0.0;    // on the contrast [1/K]
  double bias = 0.0;
  double radius_m = 0.7;  // the disc ThermalContrastAt looks in [m]
  // The confidence with the contrast; the defaults leave it as it was.
  double Fuse(double confidence, double contrast_k) const;
};

// The `thermal_evidence:` mapping of a models/thermal_evidence.yaml ({colour_weight, slope_per_k,
// bias, radius_m, and the fit's provenance, which is read past}). kInvalidArgument: missing or
// out-of-range figures.
Result<ThermalEvidence> ParseThermalEvidence(const yaml::Node& root);
// The fit that ships: agent/swarm/models/thermal_evidence.yaml, compiled in.
const ThermalEvidence& ShippedThermalEvidence();

}  // namespace swarmbox::swarm
