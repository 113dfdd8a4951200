// VictimDetector: finds people lying on the ground in a downward camera frame (8-bit BGR), with a
// classical pipeline: colour threshold -> morphological closing -> connected components -> gates
// on the blob area expected at this altitude -> a confidence per blob.
//
//   VictimDetector det;                        // reuse one per camera: scratch images are kept
//   det.Detect(bgr, fx_px / height_above_ground_m, &blobs);
//
// What a victim looks like (physics GroundRenderer, the SITL ground truth of the project): a warm
// hi-vis figure, an orange body ellipse (BGR 0,120,255; 1.44 x 0.48 m) and an amber head (BGR
// 40,210,255), about 0.59 m^2 seen from above; ground is grass/soil (R <= ~125), obstacles grey,
// sky pale blue, plus Gaussian pixel noise (std ~4 levels). The threshold keeps pixels with a
// strong red channel well above blue and green ("R high, B low"). The blob's expected area is
// person_area_m2 * pixels_per_m^2 (nadir view), or, given the camera pose, the person's area seen at
// the blob's ground point (range and incidence: tilted and oblique views): blobs far smaller or
// larger are not people.
// Confidence in [0, 1]: 0.5 + 0.49 * size_score * colour_score; a blob that touches the image border
// is a partial view, its confidence is capped at partial_confidence_cap (it cannot confirm a
// victim alone under MissionState's rule, which needs 0.9).
//
// Allocation: the scratch images are reused once they have the frame's size; OpenCV's morphology
// and connected components still allocate a few dozen small internal buffers per frame (measured
// in allocation_test.cpp). Frames come at 5 Hz, outside the control loop.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "swarmbox/swarm/geolocation.hpp"

namespace swarmbox::swarm {

struct VictimDetectorParams {
  int min_red = 170;                 // R >= this [0, 255]
  int min_red_minus_blue = 90;       // R - B >= this
  int min_red_minus_green = 20;      // R - G >= this (the amber head has R - G ~ 45)
  double person_area_m2 = 0.59;      // plan-view area of a lying person [m^2]
  double min_area_ratio = 0.3;       // blob / expected area, for blobs inside the image
  double max_area_ratio = 3.0;       // larger blobs are not a person (tarp, vehicle...)
  double full_size_ratio = 0.6;      // size score is 1 from this ratio up to full_size_max_ratio
  double full_size_max_ratio = 1.7;
  int min_area_px = 4;               // smaller blobs are noise whatever the altitude
  int border_px = 1;                 // a blob within this of the edge is a partial view
  double partial_confidence_cap = 0.8;
};

struct ImageBlob {
  Eigen::Vector2d centroid_px = Eigen::Vector2d::Zero();  // (u right, v down)
  double area_px = 0;
  double expected_area_px = 0;
  bool partial = false;        // touches the image border
  double colour_score = 0;     // [0, 1]
  double size_score = 0;       // [0, 1]
  double confidence = 0;       // [0, 1]
};

class VictimDetector {
 public:
  explicit VictimDetector(const VictimDetectorParams& params = {});

  // bgr: CV_8UC3. pixels_per_m: image scale on the ground at the image centre [px/m]
  // (fx_px / height above ground for a nadir camera), > 0. `out` is cleared first.
  void Detect(const cv::Mat& bgr, double pixels_per_m, std::vector<ImageBlob>* out);
  // Same, with the expected area of each blob from the camera pose: the person's area seen at the
  // blob's ground point, (f / range)^2 * cos(incidence) (tilted camera, oblique views).
  void Detect(const cv::Mat& bgr, const PinholeIntrinsics& k, const OpticalPose& pose,
              double ground_z_m, std::vector<ImageBlob>* out);

  const VictimDetectorParams& params() const { return params_; }
  const cv::Mat& mask() const { return mask_; }  // the last thresholded mask, for debugging

 private:
  template <typename ExpectedAreaFn>
  void DetectImpl(const cv::Mat& bgr, ExpectedAreaFn expected_area_px, std::vector<ImageBlob>* out);

  VictimDetectorParams params_;
  cv::Mat mask_, closed_, labels_, stats_, centroids_, kernel_;
};

}  // namespace swarmbox::swarm
