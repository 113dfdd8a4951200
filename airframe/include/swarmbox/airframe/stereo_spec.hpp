// StereoSpec: the active stereo depth camera of a scout (Luxonis OAK-D Pro): two global-shutter
// mono cameras a baseline apart looking down, and an IR dot projector between them: the airframe's
// `stereo:` section (Airframe::stereo, read by ParseAirframe's section reader ReadStereo, which
// calls ParseStereoSpec). Absent key: `enabled == false`, nothing is rendered, sent or matched.
//
//   auto spec = ParseStereoSpec(root.Find("stereo"));   // nullptr or null node: disabled
//   if (!spec) return spec.error();                     // file:line:col: stereo: ...
//
// Geometry: both cameras are pinholes looking along body -z like the RGB camera (CameraSpec):
// optical x = body -y (image right), optical y = body -x. The left camera sits at
// offset_m - baseline/2 along optical x, the right one at +baseline/2, so the pair is rectified
// by construction: a point at depth Z shows at u_left - u_right = f * baseline / Z.
// The projector sits at offset_m, oriented like the cameras. Figures and their sources: the
// reference file trials/sensors/oak_d_pro_stereo.yaml and physics_server/README.md "Stereo".
#pragma once

#include <string>

#include "swarmbox/airframe/vec3.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::airframe {

struct ProjectorSpec {
  bool enabled = true;
  int dot_count = 5000;              // pseudo-random dots over the field of illumination
  double foi_h_rad = 1.3614;         // field of illumination, horizontal (78 deg)
  double foi_v_rad = 1.0647;         // vertical (61 deg)
  double optical_power_w = 0.3;      // emitted in band [W]
  double dot_fill = 0.05;            // share of the field of illumination the dots cover
  double range_m = 15.0;             // nominal range: dots are drawn up to here, none beyond
};

struct StereoSpec {
  bool enabled = false;              // false: no `stereo:` key (nothing rendered, nothing costs)
  double baseline_m = 0.075;
  int width_px = 640;                // per camera
  int height_px = 400;
  double hfov_rad = 1.2566;          // 72 deg: the rectified depth HFOV (sensor 80 deg)
  double rate_hz = 5;                // pairs per simulated second
  double noise_std = 2.0;            // Gaussian read noise, 8-bit levels
  double latency_min_ms = 30;        // device latency capture -> depth on the host, uniform in
  double latency_max_ms = 50;        // [min, max] per frame
  int num_disparities = 64;          // matcher search range [px], a multiple of 16
  Vec3 offset_m{0.0, 0.0, -0.05};    // centre of the pair (and the projector), body frame [m]
  ProjectorSpec projector;

  // Focal length [px] of each camera (both equal, square pixels).
  double FocalPx() const;
};

// Parses the `stereo:` mapping. `node` == nullptr or a null node: the sensor is off (default spec
// with enabled == false). Unknown keys and out-of-range values are errors with the node's
// file:line:col. `enabled: false` inside the mapping also turns it off.
Result<StereoSpec> ParseStereoSpec(const yaml::Node* node);

}  // namespace swarmbox::airframe
