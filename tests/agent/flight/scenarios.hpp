// The closed-loop scenarios of the flight stack's acceptance criteria, shared by the tests
// (closed_loop_test.cpp asserts on them) and the `flight` benchmark suite (prints them).
// Every metric is measured on the physics world's ground truth; the controller sees sensors only.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include "swarmbox/common/result.hpp"

namespace swarmbox::flight::testing {

struct HoverMetrics {
  double rms_m = 0;          // 3-D truth error to the hold point over the window
  double max_m = 0;
  double est_rms_m = 0;      // estimator error (estimate - truth), 3-D RMS
  double window_s = 0;
};
// Takes off to 5 m, settles, then holds for window_s; optional mean wind with gusts.
Result<HoverMetrics> RunHover(std::uint64_t seed, double window_s, double wind_mps = 0.0,
                              double gust_std_mps = 0.0);

struct StepMetrics {
  double settle_s = 0;       // from the command until the truth stays within 0.2 m of the target
                             // along the step's direction (the step response)
  double settle_3d_s = 0;    // the same on the full 3-D error (includes the GPS-limited hover
                             // wander across the step, see HoverMetrics)
  double overshoot_pct = 0;  // beyond the target along the step direction, % of the step
  double peak_speed_mps = 0;
  bool settled = false;
};
// From a 5 m hover, a step of `step_m` (world ENU) to the position setpoint.
Result<StepMetrics> RunStep(std::uint64_t seed, double dx, double dy, double dz);

struct DropoutMetrics {
  double max_drift_m = 0;        // truth to hold point during the dropout
  double est_err_at_end_m = 0;   // estimator error when GPS comes back
  double max_err_after_m = 0;    // truth to hold point in the 10 s after recovery
  double final_err_m = 0;        // truth to hold point 10 s after recovery
  double max_speed_after_mps = 0;  // no violent reaction to the recovery
  bool events_ok = false;        // gps_lost and gps_recovered were reported
  bool crashed = false;
};
Result<DropoutMetrics> RunGpsDropout(std::uint64_t seed, double dropout_s);

struct TransferMetrics {
  double arrival_s = 0;          // from the command until the drone is within 1 m of the target
  double swing_at_arrival_deg = 0;
  double residual_swing_deg = 0; // max swing from arrival + 5 s to arrival + 15 s
  double max_swing_deg = 0;      // over the whole transfer
  double final_err_m = 0;
  bool crashed = false;
};
// x8_heavy with the stretcher hanging: a `distance_m` transfer east at 10 m.
// `trace` (optional): one line per second of truth, estimate and controller state.
Result<TransferMetrics> RunHeavyTransfer(std::uint64_t seed, double distance_m, bool damping,
                                         std::FILE* trace = nullptr);

}  // namespace swarmbox::flight::testing
