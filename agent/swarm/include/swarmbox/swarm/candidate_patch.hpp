// CandidatePatch: the colour patch a convolutional second stage of the victim detector sees around a
// first-stage candidate (victim_detector.hpp), at a fixed metric scale whatever the altitude. The
// trainer (tools/train_detector, --export-patches) and the detector both take their patches through
// CandidatePatchSampler, so training and inference see the same pixels.
//
//   CandidatePatchSampler patches;
//   patches.SetFrame(bgr, pixels_per_m);              // once per frame
//   patches.Extract(candidate_centre_px, &patch);      // kCnnPatchPx x kCnnPatchPx CV_8UC3 (BGR)
//
// Scale: kCnnPatchM x kCnnPatchM (3 x 3 m: a lying adult, 1.75 m, with room for an arm and a
// candidate 0.75 m off) at kCnnPxPerM (10.7 px/m: a person 19 px long). Why not 16 px/m (the blob
// features' scale, 48 x 48 px for 3 m): a network's cost grows with the pixels, 2.25 times for 48 x 48,
// and the detector runs it on up to 96 candidates per frame; 10.7 px/m is 2/3 of the camera's own
// resolution at the 30 m search altitude (640 px over 1.204 rad: 15.5 px/m) and finer than it above 44 m.
// Sampling: bilinear, the frame's border replicated; a frame finer than kCnnPxPerM is first shrunk
// to it by area averaging (once per frame), so a patch never aliases.
// A model with finer patches (VictimDetectorModel::cnn_patch_px) samples the same 3 x 3 m at
// patch_px / kCnnPatchM px/m. The shipped model's are 48 px (16 px/m, the camera's own resolution
// at 30 m: tools/train_detector README "Patches at the camera's resolution"); kCnnPatchPx is the
// default of a model file without the field.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace swarmbox::swarm {

inline constexpr int kCnnPatchPx = 32;
inline constexpr double kCnnPatchM = 3.0;
inline constexpr double kCnnPxPerM = kCnnPatchPx / kCnnPatchM;

class CandidatePatchSampler {
 public:
  // patch_px: the patch's side [px], a multiple of 8 in [16, 128] (the network pools 3 times).
  explicit CandidatePatchSampler(int patch_px = kCnnPatchPx);
  int patch_px() const { return patch_px_; }
  double px_per_m() const { return patch_px_ / kCnnPatchM; }
  // The frame (CV_8UC3 BGR, not copied: it must outlive the Extract() calls) and its ground scale
  // [px/m] > 0.
  void SetFrame(const cv::Mat& bgr, double pixels_per_m);
  // The patch centred on centre_px (a pixel of the frame, u right, v down; it may lie off the
  // image) into *patch (patch_px() x patch_px() CV_8UC3, reallocated only when it is not that).
  void Extract(const Eigen::Vector2d& centre_px, cv::Mat* patch) const;

 private:
  cv::Mat frame_;        // the frame, or its shrunk copy (small_)
  cv::Mat small_;
  double frame_px_per_m_ = 0;  // of frame_
  double to_frame_ = 1;        // frame_ pixels per input pixel
  int patch_px_ = kCnnPatchPx;
};

// Whether a patch side is one the sampler and train_cnn.py's network take.
inline bool ValidCnnPatchPx(int px) { return px >= 16 && px <= 128 && px % 8 == 0; }

// One patch of one frame (SetFrame then Extract): for tests and one-off use.
void CandidatePatch(const cv::Mat& bgr, double pixels_per_m, const Eigen::Vector2d& centre_px, cv::Mat* patch);

}  // namespace swarmbox::swarm
