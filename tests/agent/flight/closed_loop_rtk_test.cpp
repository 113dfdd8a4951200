// Closed-loop tests with an RTK receiver: the x500 of x500.yaml with its GPS switched to an
// RTK-fixed u-blox ZED-F9P (Holybro's H-RTK F9P) 1 km from its base station (sim_harness.hpp
// RigOptions::gps_fix; the error model and its datasheet figures in
// physics_server/src/sensor_models.hpp: 0.01 m + 1 ppm CEP, per axis 0.0093 m horizontally and
// 0.016 m vertically). The estimator takes the receiver's reported accuracy as its GPS noise (as
// PX4's EKF2 does), nothing else changes: same gains, same seeds as closed_loop_test.cpp (which
// keeps what the standalone receiver gives). Here the targets hold on ABSOLUTE truth:
// hover RMS < 0.1 m, the 10 m step and the 5 m climb settled within 0.2 m in < 6 s with < 10%
// overshoot. Every figure is measured on the physics world's ground truth; the controller only
// sees sensor samples. `swarmbox-bench flight` prints the same scenarios (receiver=rtk).
#include <gtest/gtest.h>

#include <cstdio>

#include "scenarios.hpp"

namespace swarmbox::flight::testing {
namespace {

class ClosedLoopRtk : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(ClosedLoopRtk, X500HoverHoldsPositionOnAbsoluteTruth) {
  auto m = RunHover(GetParam(), 30.0, 0.0, 0.0, Receiver::kRtk);
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  std::printf("seed=%llu hover receiver=rtk: truth_rms_m=%.3f rms_m=%.3f max_m=%.3f gps_wander_rms_m=%.4f "
              "est_rms_m=%.3f track_rms_m=%.3f\n",
              static_cast<unsigned long long>(GetParam()), m->truth_rms_m, m->rms_m, m->max_m,
              m->gps_wander_rms_m, m->est_rms_m, m->track_rms_m);
  // truth_rms_m: 3-D RMS of the TRUE position to the commanded hold point over 30 s, which
  // includes the estimate's absolute error (the receiver's own, ~0.01 m, plus the filter's).
  EXPECT_LT(m->truth_rms_m, 0.1);  // the target
  EXPECT_LT(m->rms_m, 0.1);        // about the held mean (receiver frame = truth within 1 cm here)
  EXPECT_LT(m->gps_wander_rms_m, 0.02);  // the RTK receiver's own wander over the window
}

TEST_P(ClosedLoopRtk, X500HorizontalStepSettlesFastWithoutOvershoot) {
  auto m = RunStep(GetParam(), 10.0, 0.0, 0.0, Receiver::kRtk);
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  std::printf("seed=%llu step10 receiver=rtk: settle_target_s=%.2f settle_truth_s=%.2f settle_s=%.2f "
              "overshoot_truth_pct=%.1f overshoot_pct=%.1f peak_m_s=%.2f\n",
              static_cast<unsigned long long>(GetParam()), m->settle_target_s, m->settle_truth_s, m->settle_s,
              m->overshoot_truth_pct, m->overshoot_pct, m->peak_speed_m_s);
  EXPECT_TRUE(m->settled);
  EXPECT_LT(m->settle_target_s, 6.0);  // true position within 0.2 m of the commanded target
  EXPECT_LT(m->settle_truth_s, 6.0);   // true displacement within 0.2 m of the step
  EXPECT_LT(m->overshoot_truth_pct, 10.0);
}

TEST_P(ClosedLoopRtk, X500ClimbSettlesFastWithoutOvershoot) {
  auto m = RunStep(GetParam(), 0.0, 0.0, 5.0, Receiver::kRtk);
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  std::printf("seed=%llu climb5 receiver=rtk: settle_target_s=%.2f settle_truth_s=%.2f settle_s=%.2f "
              "overshoot_truth_pct=%.1f overshoot_pct=%.1f peak_m_s=%.2f\n",
              static_cast<unsigned long long>(GetParam()), m->settle_target_s, m->settle_truth_s, m->settle_s,
              m->overshoot_truth_pct, m->overshoot_pct, m->peak_speed_m_s);
  EXPECT_TRUE(m->settled);
  EXPECT_LT(m->settle_target_s, 6.0);
  EXPECT_LT(m->settle_truth_s, 6.0);
  EXPECT_LT(m->overshoot_truth_pct, 10.0);
}

INSTANTIATE_TEST_SUITE_P(Seeds, ClosedLoopRtk, ::testing::Values(1u, 3u, 7u, 42u),
                         [](const ::testing::TestParamInfo<std::uint64_t>& i) {
                           return "seed" + std::to_string(i.param);
                         });

}  // namespace
}  // namespace swarmbox::flight::testing
