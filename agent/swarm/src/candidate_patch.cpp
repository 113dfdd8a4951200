#include "swarmbox/swarm/candidate_patch.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "detail/shrink_to_scale.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {

CandidatePatchSampler::CandidatePatchSampler(int patch_px) : patch_px_(patch_px) {
  SWARMBOX_CHECK(ValidCnnPatchPx(patch_px));
}

void CandidatePatchSampler::SetFrame(const cv::Mat& bgr, double pixels_per_m) {
  SWARMBOX_CHECK(bgr.type() == CV_8UC3 && !bgr.empty() && pixels_per_m > 0);
  frame_ = detail::ShrinkToScale(bgr, pixels_per_m, px_per_m(), &small_, &to_frame_);
  frame_px_per_m_ = pixels_per_m * to_frame_;
}

void CandidatePatchSampler::Extract(const Eigen::Vector2d& centre_px, cv::Mat* patch) const {
  SWARMBOX_CHECK(!frame_.empty());
  // Patch pixel (i, j) centre -> frame pixel: x = cx + (j + 0.5 - N/2) * step - 0.5 (pixel centres
  // at integers), the candidate's centre between the patch's two middle pixels.
  const double step = frame_px_per_m_ / px_per_m();  // frame_ pixels per patch pixel
  const double cx = (centre_px.x() + 0.5) * to_frame_, cy = (centre_px.y() + 0.5) * to_frame_;
  const double half = patch_px_ / 2.0;
  const cv::Matx23d patch_to_frame(step, 0, cx - half * step + 0.5 * step - 0.5,  //
                                   0, step, cy - half * step + 0.5 * step - 0.5);
  patch->create(patch_px_, patch_px_, CV_8UC3);
  cv::warpAffine(frame_, *patch, cv::Mat(patch_to_frame), patch->size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                 cv::BORDER_REPLICATE);
}

void CandidatePatch(const cv::Mat& bgr, double pixels_per_m, const Eigen::Vector2d& centre_px, cv::Mat* patch) {
  CandidatePatchSampler sampler;
  sampler.SetFrame(bgr, pixels_per_m);
  sampler.Extract(centre_px, patch);
}

}  // namespace swarmbox::swarm
