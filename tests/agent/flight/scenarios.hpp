// The closed-loop scenarios of the flight stack's acceptance criteria, shared by the tests
// (closed_loop_test.cpp asserts on them) and the `flight` benchmark suite (prints them).
// Every metric is measured on the physics world's ground truth; the controller sees sensors only.
// Position metrics come in two frames (see sim_harness.hpp): `nav` (the receiver's frame: truth
// shifted by the GPS error's own wander since take-off; what the flight stack is held to) and
// `truth` (absolute, which adds the receiver's wander no GPS-only drone can see).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include "swarmbox/common/result.hpp"
#include "swarmbox/physics/airframe.hpp"  // GpsFix

namespace swarmbox::flight::testing {

struct HoverMetrics {
  double rms_m = 0;          // 3-D RMS about the mean position over the window, receiver's frame:
                             // how well the position is held
  double max_m = 0;          // largest distance from that mean
  double target_rms_m = 0;   // 3-D RMS to the commanded hold point, receiver's frame (adds the
                             // offset between the estimate's and the receiver's frames learnt
                             // on the ground, ~0.05 m per axis with 0.2 m fix noise)
  double truth_rms_m = 0;    // the same on absolute truth
  double gps_wander_rms_m = 0;  // RMS of the receiver's horizontal error change over the window
  double est_rms_m = 0;      // estimator error (estimate - nav position), 3-D RMS
  double track_rms_m = 0;    // control tracking: the estimate to the hold point, 3-D RMS (what the
                             // controller sees; includes the estimate's per-fix steps it does not
                             // follow)
  double window_s = 0;
};
// The x500's GPS receiver in a scenario: the airframe's standalone one (x500.yaml), or an
// RTK-fixed ZED-F9P 1 km from its base (sim_harness.hpp RigOptions::gps_fix).
using Receiver = physics::GpsFix;
const char* ReceiverName(Receiver receiver);  // "standalone" | "rtk"

// Takes off to 5 m, settles, then holds for window_s; optional mean wind with gusts.
Result<HoverMetrics> RunHover(std::uint64_t seed, double window_s, double wind_m_s = 0.0,
                              double gust_std_m_s = 0.0, Receiver receiver = Receiver::kStandalone);

struct StepMetrics {         // the step response: displacement from where the drone was at the
                             // command, receiver's frame
  double settle_s = 0;       // from the command until the displacement along the step stays
                             // within 0.2 m of the step
  double settle_3d_s = 0;    // the same on the full 3-D displacement error
  double settle_truth_s = 0; // settle_s on absolute truth (the true displacement)
  double settle_target_s = 0; // until the true position stays within 0.2 m of the commanded
                              // target along the step (absolute: adds the hold offset at the
                              // command and the estimate's error)
  double overshoot_pct = 0;  // beyond the step along its direction, % of the step
  double overshoot_truth_pct = 0;  // the same on absolute truth
  double peak_speed_m_s = 0;
  bool settled = false;
};
// From a 5 m hover, a step of `step_m` (world ENU) to the position setpoint.
Result<StepMetrics> RunStep(std::uint64_t seed, double dx, double dy, double dz,
                            Receiver receiver = Receiver::kStandalone);

struct DropoutMetrics {              // receiver's frame throughout
  double max_drift_m = 0;        // position to hold point during the dropout
  double est_err_at_end_m = 0;   // estimator error when GPS comes back
  double max_err_after_m = 0;    // truth to hold point in the 10 s after recovery
  double final_err_m = 0;        // truth to hold point 10 s after recovery
  double max_speed_after_m_s = 0;  // no violent reaction to the recovery
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
// x8_heavy with the stretcher hanging: a `distance_m` transfer east at 10 m. `loaded_mass_kg`
// > 0: the stretcher is re-hooked with that mass before the rig lets go (80: stretcher and
// evacuee); 0: the airframe's empty stretcher. The controller is told 80 kg either way (its
// hover-thrust estimator learns the real load).
// `trace` (optional): one line per second of truth, estimate and controller state.
Result<TransferMetrics> RunHeavyTransfer(std::uint64_t seed, double distance_m, bool damping,
                                         std::FILE* trace = nullptr, double loaded_mass_kg = 0.0);

}  // namespace swarmbox::flight::testing
