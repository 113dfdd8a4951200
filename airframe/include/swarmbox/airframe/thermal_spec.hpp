// ThermalSpec: a downward long-wave infrared (LWIR) camera, a radiometric uncooled microbolometer
// core (Teledyne FLIR Boson 320): the `thermal:` mapping of trials/sensors/boson_320_thermal.yaml,
// which holds the figures and their sources. Absent: `enabled == false`, nothing is rendered.
//
//   auto spec = ParseThermalSpec(root.Find("thermal"));  // nullptr or null node: disabled
//   if (!spec) return spec.error();                      // file:line:col: thermal: ...
//
// Geometry as the RGB camera (CameraSpec): a pinhole looking along body -z, optical x = body -y,
// optical y = body -x, square pixels, no distortion. The image is radiometric: each pixel the
// scene's apparent temperature in hundredths of a kelvin (physics::ThermalImage), with the
// core's temporal noise (netd_k), a per-frame offset (offset_std_k: the radiometric error after
// a flat-field correction) and the optics' blur (psf_sigma_px).
#pragma once

#include "swarmbox/airframe/vec3.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::airframe {

struct ThermalSpec {
  bool enabled = false;  // false: no `thermal:` key
  int width_px = 320;
  int height_px = 256;
  double hfov_rad = 0.8399;        // 48.1 deg: 320 x 12 um behind a 4.3 mm lens
  // The core's frame rate (its slow configuration). A frame is taken with each camera frame, so
  // an airframe's camera.rate_hz may not exceed it (ParseAirframe refuses that).
  double rate_hz = 8.6;
  double netd_k = 0.05;            // temporal noise, one standard deviation [K]
  double offset_std_k = 1.0;       // a frame's radiometric offset, one standard deviation [K]
  double psf_sigma_px = 0.5;       // the optics' blur, a Gaussian's standard deviation [px]
  Vec3 offset_m{0.0, 0.0, -0.05};  // the camera centre in the body frame [m]

  double FocalPx() const;  // width_px / 2 / tan(hfov_rad / 2)
};

// Parses the `thermal:` mapping. `node` == nullptr or a null node: the camera is off (default
// spec with enabled == false). Unknown keys and out-of-range values are errors with the node's
// file:line:col. `enabled: false` inside the mapping also turns it off.
Result<ThermalSpec> ParseThermalSpec(const yaml::Node* node);

}  // namespace swarmbox::airframe
