// Per receiver: path loss with seeded shadowing, obstacles in the line of sight, PER from SNR,
// the range cut-off.
#include <gtest/gtest.h>

#include <cmath>

#include "channel_fixture.hpp"
#include "swarmbox/channel/channel.hpp"

namespace swarmbox::channel {
namespace {

using testing::CleanProfile;
using testing::LineUp;
using testing::SendStream;

RadioProfile Wifi() {
  auto p = LoadRadioProfile(testing::TrialsDir() + "/radios/wifi_5ghz_mesh.yaml");
  EXPECT_TRUE(p.ok()) << (p.ok() ? "" : p.error().ToString());
  return *p;
}

double DeliveryRatio(Channel& ch, int frames) {
  return static_cast<double>(SendStream(ch, frames, 20'000'000).size()) / frames;
}

TEST(SegmentCrossesBox, HitsMissesAndTouches) {
  const Box b{{-1, -1, 0}, {1, 1, 10}};
  EXPECT_TRUE(SegmentCrossesBox({-5, 0, 5}, {5, 0, 5}, b));
  EXPECT_FALSE(SegmentCrossesBox({-5, 0, 15}, {5, 0, 15}, b));    // above it
  EXPECT_FALSE(SegmentCrossesBox({-5, 0, 5}, {-2, 0, 5}, b));     // stops short
  EXPECT_TRUE(SegmentCrossesBox({0, 0, 5}, {0, 0, 6}, b));        // inside
  EXPECT_TRUE(SegmentCrossesBox({-5, 1, 5}, {5, 1, 5}, b));       // grazes a face
  EXPECT_FALSE(SegmentCrossesBox({-5, 3, 5}, {5, 3, 5}, b));      // parallel, beside it
  EXPECT_TRUE(SegmentCrossesBox({-5, -5, 12}, {5, 5, 2}, b));     // diagonal, going down through
}

TEST(SegmentCrossesBox, YawTurnsTheBoxAboutItsCentre) {
  const Box thin{{-1, -10, 0}, {1, 10, 10}};
  Box turned = thin;
  turned.yaw_rad = std::acos(-1.0) / 2;  // now long in x, thin in y
  EXPECT_FALSE(SegmentCrossesBox({5, -20, 5}, {5, 20, 5}, thin));
  EXPECT_TRUE(SegmentCrossesBox({5, -20, 5}, {5, 20, 5}, turned));
  EXPECT_TRUE(SegmentCrossesBox({-20, 5, 5}, {20, 5, 5}, thin));
  EXPECT_FALSE(SegmentCrossesBox({-20, 5, 5}, {20, 5, 5}, turned));
}

TEST(ChannelLink, PerRisesWithDistance) {
  RadioProfile p = Wifi();
  p.path_loss.shadowing_sigma_db = 0;
  Channel ch(p, 2, 1, {});
  double last = 0;
  for (double d = 50; d <= 750; d += 25) {
    ch.SetPositions(LineUp(2, d));
    const LinkState l = ch.Link(0, 1);
    EXPECT_GE(l.per, last) << d;
    last = l.per;
  }
  ch.SetPositions(LineUp(2, 100));
  EXPECT_LT(ch.Link(0, 1).per, 1e-6);
  ch.SetPositions(LineUp(2, RangeForPer(p, 0.5)));
  EXPECT_NEAR(ch.Link(0, 1).per, 0.5, 1e-9);
  ch.SetPositions(LineUp(2, 700));
  EXPECT_GT(ch.Link(0, 1).per, 0.99);
}

TEST(ChannelLink, DeliveryRatioFollowsThePer) {
  RadioProfile p = Wifi();
  p.path_loss.shadowing_sigma_db = 0;
  for (double per : {0.1, 0.5, 0.9}) {
    Channel ch(p, 2, 3, {});
    ch.SetPositions(LineUp(2, RangeForPer(p, per)));
    EXPECT_NEAR(DeliveryRatio(ch, 4000), 1.0 - per, 0.03) << "PER " << per;  // binomial sd <= 0.008
    EXPECT_EQ(ch.stats().lost_per + ch.stats().delivered, 4000u);
  }
}

TEST(ChannelLink, NothingArrivesBeyondMaxRange) {
  RadioProfile p = CleanProfile();
  p.max_range_m = 300;  // PER at 300 m is ~1e-9: the cut-off alone decides
  Channel near(p, 2, 1, {});
  near.SetPositions(LineUp(2, 299));
  EXPECT_EQ(DeliveryRatio(near, 1000), 1.0);
  Channel far(p, 2, 1, {});
  far.SetPositions(LineUp(2, 301));
  EXPECT_EQ(DeliveryRatio(far, 1000), 0.0);
  EXPECT_EQ(far.stats().lost_range, 1000u);
  EXPECT_FALSE(far.Link(0, 1).in_range);
  EXPECT_EQ(far.Link(0, 1).per, 1.0);
}

TEST(ChannelLink, TheWifiMeshLosesItsPeerAtItsRangeAndFindsItAgain) {
  Channel ch(Wifi(), 2, 5, {});
  ch.SetPositions(LineUp(2, 100));
  EXPECT_GT(DeliveryRatio(ch, 500), 0.99);
  ch.SetPositions(LineUp(2, Wifi().max_range_m + 10));
  const auto lost_before = ch.stats().lost_range;
  EXPECT_EQ(DeliveryRatio(ch, 500), 0.0);
  EXPECT_EQ(ch.stats().lost_range - lost_before, 500u);
  ch.SetPositions(LineUp(2, 100));
  EXPECT_GT(DeliveryRatio(ch, 500), 0.99);
}

TEST(ChannelLink, ShadowingIsSymmetricStableInACellAndLogNormal) {
  const RadioProfile p = Wifi();  // sigma 3 dB, 20 m cells
  Channel ch(p, 2, 9, {});
  ch.SetPositions(std::vector<Vec3d>{{1, 1, 21}, {301, 1, 21}});
  const double x = ch.Link(0, 1).shadowing_db;
  EXPECT_EQ(ch.Link(1, 0).shadowing_db, x);
  ch.SetPositions(std::vector<Vec3d>{{15, 12, 35}, {305, 9, 25}});  // same cells
  EXPECT_EQ(ch.Link(0, 1).shadowing_db, x);
  // Over many cells: mean 0, sd sigma.
  double sum = 0, sq = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    ch.SetPositions(std::vector<Vec3d>{{0, 0, 20}, {25.0 * i, 300, 20}});
    const double s = ch.Link(0, 1).shadowing_db;
    sum += s;
    sq += s * s;
  }
  const double mean = sum / n;
  EXPECT_NEAR(mean, 0.0, 0.2);
  EXPECT_NEAR(std::sqrt(sq / n - mean * mean), p.path_loss.shadowing_sigma_db, 0.15);
}

TEST(ChannelLink, AnObstacleCostsTheProfilesObstacleLoss) {
  const RadioProfile p = Wifi();
  const std::vector<Vec3d> pos{{0, 0, 20}, {100, 0, 20}};
  const Box wall{{45, -30, 0}, {55, 30, 40}};
  Channel open(p, 2, 11, {});
  Channel walled(p, 2, 11, {wall});
  Channel twice(p, 2, 11, {wall, Box{{70, -30, 0}, {72, 30, 40}}});
  open.SetPositions(pos);
  walled.SetPositions(pos);
  twice.SetPositions(pos);
  EXPECT_EQ(open.Link(0, 1).obstacles, 0);
  EXPECT_EQ(walled.Link(0, 1).obstacles, 1);
  EXPECT_NEAR(open.Link(0, 1).snr_db - walled.Link(0, 1).snr_db, p.obstacle_loss_db, 1e-9);
  EXPECT_NEAR(open.Link(0, 1).snr_db - twice.Link(0, 1).snr_db, 2 * p.obstacle_loss_db, 1e-9);
  // 100 m: ~15 dB SNR in the open, ~-5 dB behind the wall.
  EXPECT_GT(DeliveryRatio(open, 1000), 0.99);
  EXPECT_LT(DeliveryRatio(walled, 1000), 0.01);
  EXPECT_GT(walled.stats().lost_per, 990u);
  // Flying over the wall clears the line of sight.
  walled.SetPositions(std::vector<Vec3d>{{0, 0, 50}, {100, 0, 50}});
  EXPECT_EQ(walled.Link(0, 1).obstacles, 0);
}

}  // namespace
}  // namespace swarmbox::channel
