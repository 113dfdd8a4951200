#include "swarmbox/faults/gilbert_elliott_loss.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace swarmbox::faults {
namespace {

struct LossRun {
  double loss = 0.0;          // fraction lost
  double mean_burst = 0.0;    // mean length of a run of consecutive losses [packets]
};

LossRun Simulate(const GilbertElliott& model, std::uint64_t seed, int packets) {
  GilbertElliottLoss ge(model, seed);
  int lost = 0, bursts = 0;
  bool previous = false;
  for (int i = 0; i < packets; ++i) {
    const bool l = ge.Lose();
    lost += l;
    if (l && !previous) ++bursts;
    previous = l;
  }
  return {static_cast<double>(lost) / packets, bursts > 0 ? static_cast<double>(lost) / bursts : 0.0};
}

TEST(GilbertElliottLoss, LosesTheStationaryFractionInBursts) {
  // netem "loss gemodel 2% 25% 100% 0%": bad spells of 1 / r = 4 packets on average, every lost
  // packet in one; stationary loss p / (p + r) = 0.02 / 0.27 = 7.4 %.
  const GilbertElliott model{0.02, 0.25, 1.0, 0.0};
  EXPECT_NEAR(StationaryLoss(model), 0.0741, 1e-4);
  const LossRun run = Simulate(model, 42, 200000);
  // The state sequence is a Markov chain: the loss estimate's sd over 200,000 packets is about
  // sqrt(pi (1 - pi) (2 - p - r) / ((p + r) n)) = 0.16 %; allow 4 of them.
  EXPECT_NEAR(run.loss, 0.0741, 0.0065);
  // Burst length is geometric with mean 1 / r = 4 (about 3,700 bursts: sd 0.06); allow 0.3.
  EXPECT_NEAR(run.mean_burst, 4.0, 0.3);
}

TEST(GilbertElliottLoss, LossInTheGoodStateAndPartialLossInTheBadOne) {
  // A good state that drops 1 % and a bad one that drops half: (0.2 x 0.01 + 0.05 x 0.5) / 0.25.
  const GilbertElliott model{0.05, 0.2, 0.5, 0.01};
  EXPECT_NEAR(StationaryLoss(model), 0.108, 1e-9);
  EXPECT_NEAR(Simulate(model, 7, 200000).loss, 0.108, 0.006);
}

TEST(GilbertElliottLoss, NeverLeavingTheGoodStateLosesNothing) {
  const GilbertElliott model{0.0, 1.0, 1.0, 0.0};
  EXPECT_EQ(StationaryLoss(model), 0.0);
  GilbertElliottLoss ge(model, 1);
  for (int i = 0; i < 10000; ++i) ASSERT_FALSE(ge.Lose());
  EXPECT_FALSE(ge.bad());
}

TEST(GilbertElliottLoss, SameSeedSameLosses) {
  const GilbertElliott model{0.1, 0.3, 0.8, 0.05};
  GilbertElliottLoss a(model, 99), b(model, 99), c(model, 100);
  int differ = 0;
  for (int i = 0; i < 1000; ++i) {
    const bool la = a.Lose();
    ASSERT_EQ(la, b.Lose());
    differ += la != c.Lose();
  }
  EXPECT_GT(differ, 0);
}

}  // namespace
}  // namespace swarmbox::faults
