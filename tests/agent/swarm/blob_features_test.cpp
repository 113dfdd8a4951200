// The victim detector's blob features (blob_features.hpp): sizes come out in metres whatever the
// frame's scale and the thing's heading, a person-like figure and a tarp differ where the features
// say they should, and plain ground has no blob to speak of.
#include "swarmbox/swarm/blob_features.hpp"

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace swarmbox::swarm {
namespace {

// Indices into the features (the order of blob_features.hpp).
constexpr int kFound = 0, kAreaM2 = 1, kMajorM = 2, kMinorM = 3, kElongation = 4, kExtent = 5;
constexpr int kMinorPartShare = 1 + 8 + 13 + 2 * kBlobProfileBins, kMinorPartAlongAxis = kMinorPartShare + 2;

const cv::Scalar kGround(60, 110, 80);     // grass, BGR
const cv::Scalar kJacket(40, 70, 110);     // brown
const cv::Scalar kTrousers(30, 35, 40);    // dark
const cv::Scalar kSkin(130, 160, 215);
const cv::Scalar kTarp(20, 90, 230);       // orange

// A frame of `ppm` px/m with a lying figure at the centre, heading `heading_rad`: legs, a jacket
// and a head along 1.75 m, as the renderer's lying pose is laid out.
cv::Mat Figure(double ppm, double heading_rad) {
  cv::Mat img(360, 640, CV_8UC3, kGround);
  const cv::Point2d c(320, 180), h(std::cos(heading_rad), std::sin(heading_rad));
  auto at = [&](double along_m) { return c + along_m * ppm * h; };
  const float deg = static_cast<float>(heading_rad * 180 / std::numbers::pi);
  auto ellipse = [&](double along_m, double length_m, double width_m, const cv::Scalar& colour) {
    const cv::Point2d p = at(along_m);
    cv::ellipse(img, cv::RotatedRect(cv::Point2f(static_cast<float>(p.x), static_cast<float>(p.y)),
                                     cv::Size2f(static_cast<float>(length_m * ppm), static_cast<float>(width_m * ppm)), deg),
                colour, cv::FILLED, cv::LINE_AA);
  };
  ellipse(-0.45, 0.85, 0.4, kTrousers);
  ellipse(0.25, 0.66, 0.42, kJacket);
  ellipse(0.75, 0.23, 0.19, kSkin);
  return img;
}

// A 2 x 1.5 m tarp at the centre, heading `heading_rad`.
cv::Mat Tarp(double ppm, double heading_rad) {
  cv::Mat img(360, 640, CV_8UC3, kGround);
  const cv::RotatedRect r(cv::Point2f(320, 180), cv::Size2f(static_cast<float>(2.0 * ppm), static_cast<float>(1.5 * ppm)),
                          static_cast<float>(heading_rad * 180 / std::numbers::pi));
  cv::Point2f p[4];
  r.points(p);
  const std::vector<cv::Point> poly(p, p + 4);
  cv::fillConvexPoly(img, poly, kTarp, cv::LINE_AA);
  return img;
}

void AddNoise(cv::Mat& img, double sigma, std::uint64_t seed) {
  cv::Mat noise(img.size(), CV_16SC3);
  cv::theRNG().state = seed;
  cv::randn(noise, 0, sigma);
  cv::Mat sum;
  img.convertTo(sum, CV_16SC3);
  sum += noise;
  sum.convertTo(img, CV_8UC3);
}

std::vector<float> Features(const cv::Mat& img, double ppm) {
  BlobFeatureExtractor blob;
  blob.SetFrame(img, ppm);
  std::vector<float> f(kBlobFeatures);
  blob.Extract({320.0, 180.0}, f.data());
  return f;
}

TEST(VictimBlobFeatures, AFigureIsMeasuredInMetresAtEveryScaleAndHeading) {
  for (double ppm : {8.0, 15.5, 46.0}) {
    for (double heading : {0.0, 0.6, 1.9}) {
      cv::Mat img = Figure(ppm, heading);
      AddNoise(img, 4.0, 7);
      const std::vector<float> f = Features(img, ppm);
      const std::string where = "ppm " + std::to_string(ppm) + " heading " + std::to_string(heading);
      ASSERT_EQ(f[kFound], 1.0f) << where;
      EXPECT_NEAR(f[kMajorM], 1.75, 0.35) << where;   // feet to the top of the head
      EXPECT_NEAR(f[kMinorM], 0.45, 0.2) << where;
      // The frame's own blur (an antialiased edge, upsampled below 16 px/m) widens the outline
      // by about a frame pixel: 0.5 / ppm m on each side of a ~4 m outline.
      EXPECT_NEAR(f[kAreaM2], 0.6, 0.2 + 2.0 / ppm) << where;
      EXPECT_LT(f[kElongation], 0.4) << where;
      EXPECT_EQ(f[kBlobFeatures - 1], static_cast<float>(ppm)) << where;
    }
  }
}

TEST(VictimBlobFeatures, ATarpIsBiggerSquarerAndOfOneColour) {
  const double ppm = 15.5;  // 30 m with the x500 camera
  cv::Mat person = Figure(ppm, 0.4), tarp = Tarp(ppm, 0.4);
  AddNoise(person, 4.0, 1);
  AddNoise(tarp, 4.0, 1);
  const std::vector<float> p = Features(person, ppm), t = Features(tarp, ppm);
  ASSERT_EQ(t[kFound], 1.0f);
  EXPECT_NEAR(t[kAreaM2], 3.0, 0.5);
  EXPECT_GT(t[kElongation], 0.6);
  EXPECT_GT(t[kExtent], 0.85);  // a rectangle fills the box on its axes
  EXPECT_LT(p[kExtent], t[kExtent]);
  // The person's parts of another colour (legs, head) sit toward an end of its axis.
  EXPECT_GT(p[kMinorPartShare], 0.05);
  EXPECT_GT(p[kMinorPartAlongAxis], 0.15);
}

TEST(VictimBlobFeatures, PlainGroundHasNoBlobToSpeakOf) {
  cv::Mat img(360, 640, CV_8UC3, kGround);
  AddNoise(img, 8.0, 3);
  const std::vector<float> f = Features(img, 15.5);
  EXPECT_LT(f[kAreaM2], 0.05);
}

TEST(VictimBlobFeatures, ACandidateOffTheFrameReplicatesTheBorder) {
  const cv::Mat img = Figure(15.5, 0.0);
  BlobFeatureExtractor blob;
  blob.SetFrame(img, 15.5);
  std::vector<float> f(kBlobFeatures);
  blob.Extract({-5.0, 400.0}, f.data());  // below-left of the image: only ground
  EXPECT_LT(f[kAreaM2], 0.05);
}

}  // namespace
}  // namespace swarmbox::swarm
