// BlobFeatures: what the thing under a first-stage candidate of the victim detector looks like,
// as rotation-invariant numbers for the second stage (victim_detector.hpp): its size in metres,
// shape, colour variety and parts, and the orientation of its edges relative to its own axis.
//
//   BlobFeatureExtractor blob;
//   blob.SetFrame(bgr, pixels_per_m);            // once per frame
//   blob.Extract(candidate_centre_px, out);      // kBlobFeatures values per candidate
//
// Why: the window features (aggregated channel cells, victim_detector_model.hpp) are fixed to the
// image axes, and a person lies at any heading: with ~2,000 positives the forest cannot learn a
// person at every rotation, and it cannot tell an orange person from an orange tarp, cone or
// backpack by colour (BENCHMARKS.md "Where the recall is lost"). A person, seen from above, is
// ~1.75 x 0.5 m, made of parts of different colours (hair and skin at one end, trousers at the
// other), and narrow at the head; a tarp is a uniform rectangle (one fold), a cone or a backpack is
// small, a plank is long and thin with parallel edges, a rock is a roundish blob in shades of one
// colour. The features measure these things; the forest learns from them (no threshold on a
// colour here).
//
// How (per candidate, a fixed cost of kBlobPatchPx^2 pixels):
//   1. patch: kBlobPatchM x kBlobPatchM around the candidate, sampled at kBlobPxPerM from the frame
//      (the frame shrunk to kBlobPxPerM once when it is finer, so the patch never aliases), CIE Lab;
//   2. background: the per-channel median of the patch's outer ring (kRingM wide), and how much
//      the ring itself varies (the ground's texture);
//   3. segmentation: each pixel's Lab distance from the background, thresholded at the larger of
//      Otsu's threshold and the ring's mean + kRingSigmas ring standard deviations (both measured
//      on this patch); the blob is the 8-connected region grown from the most distinct pixel near
//      the centre;
//   4. features (kBlobFeatures, in the order BlobFeatureExtractor::Extract writes them):
//      found; area [m^2]; major and minor axis [m] (of the ellipse with the blob's second
//      moments); minor / major; extent (area over the box on its principal axes); perimeter^2 /
//      (4 pi area); share of the blob on the patch edge; centroid offset from the candidate [m];
//      mean Lab; mean Lab minus the background; Lab standard deviations; mean distance over the
//      threshold; the threshold; the ring's mean and standard deviation of distance;
//      kBlobProfileBins widths [m] along the major axis and as many colour distances of those
//      slices from the blob's mean (the slice most unlike the blob first: a head or a pair of
//      legs); two-means of the blob's colours: the smaller part's share, the parts' colour
//      distance, the smaller part's position along the axis (|u| / major) and its spread [m],
//      each part's Lab minus the background (smaller part first: a shadow is the ground, darker);
//      kBlobOrientationBins gradient-orientation histogram relative to the major axis over the
//      blob's box (magnitude-weighted, normalised); mean gradient inside the blob, on its edge and
//      on the ring; share of the rest of the patch's centre that is foreground too; the frame's
//      scale [px/m].
// No allocation per candidate: the scratch buffers are sized once.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace swarmbox::swarm {

inline constexpr double kBlobPxPerM = 16.0;  // a 1.75 m person is 28 px long in the patch
inline constexpr double kBlobPatchM = 4.0;   // a lying person with room for an arm and a shift
inline constexpr int kBlobPatchPx = 64;      // kBlobPatchM * kBlobPxPerM
inline constexpr int kBlobProfileBins = 6;
inline constexpr int kBlobOrientationBins = 8;
// found 1, shape 8, colour 13, profile 2 x bins, parts 10, edges bins + 4, scale 1.
inline constexpr int kBlobFeatures = 1 + 8 + 13 + 2 * kBlobProfileBins + 10 + kBlobOrientationBins + 4 + 1;
static_assert(kBlobPatchPx == static_cast<int>(kBlobPatchM * kBlobPxPerM));

class BlobFeatureExtractor {
 public:
  BlobFeatureExtractor();

  // The frame (CV_8UC3 BGR) the next Extract() calls look at, and its ground scale [px/m] > 0.
  void SetFrame(const cv::Mat& bgr, double pixels_per_m);
  // kBlobFeatures values into out for the thing nearest centre_px (a pixel of the frame, u right,
  // v down; it may lie off the image: the border is replicated).
  void Extract(const Eigen::Vector2d& centre_px, float* out);

 private:
  // The segmented blob's moments and colour sums (pixel units of the patch).
  struct Moments {
    double n = 0, x = 0, y = 0, xx = 0, yy = 0, xy = 0;
    std::array<double, 3> lab{}, lab2{};
    double distance = 0;
  };
  // The blob's principal axes: centroid, angle, and extents along them [patch px].
  struct Axes {
    double cx = 0, cy = 0, cos_a = 1, sin_a = 0, major_px = 0, minor_px = 0;
    double u_min = 0, u_max = 0, v_min = 0, v_max = 0;
    double U(int k) const;  // coordinate along the major axis of patch pixel k
    double V(int k) const;
  };

  void SamplePatch(const Eigen::Vector2d& centre_px);
  void Gradients();
  void Background(double* ring_mean, double* ring_std);
  double Threshold(double ring_mean, double ring_std) const;
  bool GrowBlob(double threshold);
  bool OnBoundary(int k) const;
  Moments BlobMoments() const;
  Axes PrincipalAxes(const Moments& m) const;
  void ShapeFeatures(const Moments& m, const Axes& axes, float*& out) const;
  void ColourFeatures(const Moments& m, double threshold, double ring_mean, double ring_std, float*& out) const;
  void ProfileFeatures(const Moments& m, const Axes& axes, float*& out) const;
  using Colours = std::array<std::array<double, 3>, 2>;
  std::array<double, 2> TwoMeans(const Moments& m, Colours* centre);
  void PartFeatures(const Moments& m, const Axes& axes, float*& out);
  void EdgeFeatures(const Axes& axes, double threshold, float*& out) const;

  cv::Mat small_, lab_;            // the frame at <= kBlobPxPerM, and in Lab (8-bit)
  double frame_to_lab_ = 1;        // lab_ pixels per frame pixel
  double pixels_per_m_ = 0;        // of the frame
  std::vector<float> l_, a_, b_;   // the patch, Lab (8-bit scale), row-major
  std::vector<float> distance_;    // Lab distance from the background
  std::vector<float> gx_, gy_;     // gradient of L
  std::vector<std::uint8_t> blob_; // 1: in the blob
  std::vector<std::uint8_t> part_; // two-means: 1 in the second colour cluster
  std::vector<int> stack_;         // region growing
  std::vector<int> members_;       // the blob's pixels
  std::vector<float> ring_[3];     // the ring's values (median)
  std::array<float, 3> background_{};
};

}  // namespace swarmbox::swarm
