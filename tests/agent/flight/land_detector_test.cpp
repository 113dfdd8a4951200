// LandDetector (the role of PX4's MulticopterLandDetector): the in-air latch that lets the hover
// thrust estimator learn, the ground-contact phase after arming, and touch-down in Land after the
// trigger time, each from its named threshold.
#include "swarmbox/flight/land_detector.hpp"

#include <gtest/gtest.h>

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {
namespace {

constexpr double kDt = 0.004;
constexpr double kMassKg = 2.0;
constexpr double kWeightN = kMassKg * kGravity_m_s2;

TEST(LandDetector, InAirLatchesOnceArmedLongEnoughAndClimbedOrSinking) {
  LandDetector ld;
  const LandDetectorParams& p = ld.params();
  EXPECT_FALSE(ld.InAir(p.in_air_after_s - kDt, 10.0, 0.0));   // high, but armed too briefly
  EXPECT_FALSE(ld.InAir(p.in_air_after_s + kDt, p.in_air_height_m - 0.01, 0.0));  // not high enough
  EXPECT_TRUE(ld.InAir(p.in_air_after_s + kDt, p.in_air_height_m + 0.01, 0.0));
  EXPECT_TRUE(ld.InAir(p.in_air_after_s + kDt, 0.0, 0.0));     // latched
  ld.Reset();                                                  // the next take-off
  EXPECT_FALSE(ld.in_air());
  EXPECT_TRUE(ld.InAir(p.in_air_after_s + kDt, 0.0, -p.sinking_m_s - 0.01));  // an airborne start sinking
}

TEST(LandDetector, GroundContactPhaseIsTheFirstMomentsAfterArming) {
  LandDetector ld;
  EXPECT_TRUE(ld.GroundContactPhase(0.0));
  EXPECT_TRUE(ld.GroundContactPhase(ld.params().ground_contact_s - kDt));
  EXPECT_FALSE(ld.GroundContactPhase(ld.params().ground_contact_s));
}

TEST(LandDetector, TouchdownNeedsStillLowThrustAndADescentCommandForTheTriggerTime) {
  LandDetector ld;
  const LandDetectorParams& p = ld.params();
  const double low_thrust_n = 0.5 * kWeightN;
  ld.StartLanding();
  // Just entered Land: the settle time has not passed, nothing counts.
  EXPECT_FALSE(ld.UpdateTouchdown(kDt, p.land_settle_s - kDt, 0.0, -0.3, low_thrust_n, kMassKg));
  // Settled in Land, still, asked down, thrust low: landed after trigger_time_s, not before.
  double t = 0.0;
  bool landed = false;
  while (!landed && t < 3.0) {
    t += kDt;
    landed = ld.UpdateTouchdown(kDt, 2.0 + t, 0.0, -0.3, low_thrust_n, kMassKg);
  }
  EXPECT_TRUE(landed);
  EXPECT_NEAR(t, p.trigger_time_s, 2 * kDt);
}

TEST(LandDetector, AnyLandedConditionFailingRestartsTheTimer) {
  LandDetector ld;
  const LandDetectorParams& p = ld.params();
  const double low_thrust_n = 0.5 * kWeightN;
  ld.StartLanding();
  for (int i = 0; i < 200; ++i) ASSERT_FALSE(ld.UpdateTouchdown(kDt, 2.0, 0.0, -0.3, low_thrust_n, kMassKg));
  // Still descending, hover thrust, or no descent asked: each resets the count.
  EXPECT_FALSE(ld.UpdateTouchdown(kDt, 2.0, -(p.vz_max_m_s + 0.01), -0.3, low_thrust_n, kMassKg));
  for (int i = 0; i < 200; ++i) ASSERT_FALSE(ld.UpdateTouchdown(kDt, 2.0, 0.0, -0.3, low_thrust_n, kMassKg));
  EXPECT_FALSE(ld.UpdateTouchdown(kDt, 2.0, 0.0, -0.3, p.low_thrust_ratio * kWeightN + 0.01, kMassKg));
  for (int i = 0; i < 200; ++i) ASSERT_FALSE(ld.UpdateTouchdown(kDt, 2.0, 0.0, -0.3, low_thrust_n, kMassKg));
  EXPECT_FALSE(ld.UpdateTouchdown(kDt, 2.0, 0.0, -p.descend_cmd_m_s + 0.01, low_thrust_n, kMassKg));
  // 200 steps (0.8 s) since the last reset: not yet; the trigger time after it: landed.
  for (int i = 0; i < 200; ++i) ASSERT_FALSE(ld.UpdateTouchdown(kDt, 2.0, 0.0, -0.3, low_thrust_n, kMassKg));
  bool landed = false;
  for (int i = 0; i < 60 && !landed; ++i) landed = ld.UpdateTouchdown(kDt, 2.0, 0.0, -0.3, low_thrust_n, kMassKg);
  EXPECT_TRUE(landed);
}

}  // namespace
}  // namespace swarmbox::flight
