// HoverThrustEstimator (PX4's zero-order hover thrust EKF) on synthetic, seeded measurements:
// a_z = g * thrust / h_true - g + noise. Deterministic: fixed seeds, fixed step.
#include "swarmbox/flight/hover_thrust_estimator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {
namespace {

constexpr double kDt = 0.004;  // the controller's 250 Hz step

// Feeds `seconds` of measurements from a vehicle whose true hover thrust is `h_true`, flown with
// `thrust(t)` (normalised), the acceleration with white noise of `noise_std` [m/s^2].
class Feed {
 public:
  explicit Feed(std::uint32_t seed) : rng_(seed) {}
  template <typename ThrustFn>
  void Run(HoverThrustEstimator& hte, double h_true, double seconds, double noise_std, ThrustFn thrust) {
    std::normal_distribution<double> n(0.0, noise_std);
    const int steps = static_cast<int>(std::lround(seconds / kDt));
    for (int k = 0; k < steps; ++k) {
      const double u = thrust(t_);
      const double acc = kGravity_m_s2 * u / h_true - kGravity_m_s2 + n(rng_);
      hte.Predict(kDt);
      hte.Fuse(acc, u, kDt);
      t_ += kDt;
    }
  }
  double t() const { return t_; }

 private:
  std::mt19937 rng_;
  double t_ = 0.0;
};

TEST(HoverThrustEstimator, ConvergesToTheTrueHoverThrustFromAWrongStart) {
  // Given a vehicle that hovers at 0.35 of its thrust, a filter started at PX4's 0.5 default and
  // a thrust that wobbles around hover (a position loop at work),
  HoverThrustEstimator hte;
  hte.Reset(0.5);
  Feed feed(7);
  // when it flies 10 s with 1 m/s^2 acceleration noise,
  feed.Run(hte, 0.35, 10.0, 1.0, [](double t) { return 0.35 + 0.05 * std::sin(2.0 * t); });
  // then the estimate is within 1 % of the thrust range and confident.
  EXPECT_NEAR(hte.hover_thrust(), 0.35, 0.01);
  EXPECT_LT(std::sqrt(hte.variance()), 0.01);
}

TEST(HoverThrustEstimator, IsExactWithoutNoise) {
  HoverThrustEstimator hte;
  hte.Reset(0.3);
  Feed feed(1);
  feed.Run(hte, 0.42, 20.0, 0.0, [](double t) { return 0.42 + 0.1 * std::sin(3.0 * t); });
  EXPECT_NEAR(hte.hover_thrust(), 0.42, 1e-3);
}

TEST(HoverThrustEstimator, FollowsALoadChangeWithoutBeingTold) {
  // Given a converged estimate for the lifter with its empty stretcher (h = 0.33),
  HoverThrustEstimator hte;
  hte.Reset(0.33);
  Feed feed(3);
  auto hover = [](double h) { return [h](double t) { return h + 0.02 * std::sin(1.5 * t); }; };
  feed.Run(hte, 0.33, 20.0, 1.0, hover(0.33));
  ASSERT_NEAR(hte.hover_thrust(), 0.33, 0.01);
  // when the evacuee goes on (h = 0.53) and the position loop's integrator raises the thrust to
  // hold the height, the innovations fail the gate on one side: the change detector widens the
  // variance and the estimate follows within seconds;
  feed.Run(hte, 0.53, 8.0, 1.0, hover(0.53));
  EXPECT_NEAR(hte.hover_thrust(), 0.53, 0.02);
  // and back down after a release.
  feed.Run(hte, 0.30, 8.0, 1.0, hover(0.30));
  EXPECT_NEAR(hte.hover_thrust(), 0.30, 0.02);
}

TEST(HoverThrustEstimator, APriorIsCorrectedWhenItIsWrong) {
  // Given a converged estimate and then a prior announcing 80 kg more (the attach) which the
  // world did not take (a refused hook),
  HoverThrustEstimator hte;
  hte.Reset(0.33);
  Feed feed(11);
  auto hover = [](double t) { return 0.33 + 0.02 * std::sin(1.5 * t); };
  feed.Run(hte, 0.33, 10.0, 1.0, hover);
  hte.SetPrior(0.53, 0.1);
  EXPECT_NEAR(hte.hover_thrust(), 0.53, 1e-12);
  EXPECT_NEAR(std::sqrt(hte.variance()), 0.1, 1e-12);
  // then 2 s of flight bring it back to what the drone lifts.
  feed.Run(hte, 0.33, 2.0, 1.0, hover);
  EXPECT_NEAR(hte.hover_thrust(), 0.33, 0.02);
}

TEST(HoverThrustEstimator, StaysWithinItsBoundsAndIgnoresBadInput) {
  HoverThrustParams p;
  p.min_hover = 0.2;
  p.max_hover = 0.6;
  HoverThrustEstimator hte(p);
  hte.Reset(0.95);
  EXPECT_DOUBLE_EQ(hte.hover_thrust(), 0.6);
  Feed feed(5);
  feed.Run(hte, 0.8, 10.0, 0.5, [](double) { return 0.8; });  // heavier than the bounds allow
  EXPECT_DOUBLE_EQ(hte.hover_thrust(), 0.6);
  const double before = hte.hover_thrust();
  const HoverThrustStatus st = hte.Fuse(std::nan(""), 0.5, kDt);
  EXPECT_FALSE(st.fused);
  EXPECT_FALSE(hte.Fuse(0.0, 0.0, kDt).fused);  // no thrust: nothing to learn
  EXPECT_DOUBLE_EQ(hte.hover_thrust(), before);
}

TEST(HoverThrustEstimator, IsDeterministic) {
  auto run = [] {
    HoverThrustEstimator hte;
    hte.Reset(0.5);
    Feed feed(42);
    feed.Run(hte, 0.4, 5.0, 2.0, [](double t) { return 0.4 + 0.05 * std::cos(t); });
    return hte.hover_thrust();
  };
  EXPECT_EQ(run(), run());
}

TEST(HoverThrustEstimator, HighNoiseScaleSlowsLearning) {
  // De-weighted measurements (PX4: fast climbs) move the estimate less over the same time.
  auto learnt = [](double scale) {
    HoverThrustEstimator hte;
    hte.Reset(0.5);
    for (int k = 0; k < 250; ++k) {
      hte.Predict(kDt);
      hte.Fuse(kGravity_m_s2 * 0.4 / 0.4 - kGravity_m_s2, 0.4, kDt, scale);
    }
    return 0.5 - hte.hover_thrust();
  };
  EXPECT_GT(learnt(1.0), learnt(4.0));
  EXPECT_GT(learnt(4.0), 0.0);
}

}  // namespace
}  // namespace swarmbox::flight
