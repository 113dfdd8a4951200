#include "swarmbox/swarm/victim_detector.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {
namespace {

// Non-maximum suppression, most confident first: appends to `out` each blob of `blobs` (sorted
// here) not within `radius_px` of one kept before it.
void SuppressNonMaxima(std::vector<ImageBlob>* blobs, double radius_px, std::vector<ImageBlob>* out) {
  std::stable_sort(blobs->begin(), blobs->end(),
                   [](const ImageBlob& a, const ImageBlob& b) { return a.confidence > b.confidence; });
  const double r2 = std::pow(radius_px, 2);
  for (const ImageBlob& b : *blobs) {
    bool suppressed = false;
    for (const ImageBlob& kept : *out) suppressed = suppressed || (kept.centroid_px - b.centroid_px).squaredNorm() < r2;
    if (!suppressed) out->push_back(b);
  }
}

// The local maxima of `valid` (its dilation `dilated`: over 3 x 3 cells or the wider square of
// VictimDetectorParams::candidate_spacing_m) at or above `threshold`, each peak
// refined to a fraction of a cell, appended to *out.
void LocalMaxima(const cv::Mat& valid, const cv::Mat& dilated, double threshold,
                 std::vector<VictimDetector::Candidate>* out) {
  const int rows = valid.rows, cols = valid.cols;
  for (int r = 0; r < rows; ++r) {
    const float* s = valid.ptr<float>(r);
    const float* d = dilated.ptr<float>(r);
    for (int c = 0; c < cols; ++c) {
      if (s[c] < threshold || s[c] < d[c]) continue;
      VictimDetector::Candidate cand{r, c, s[c], static_cast<double>(r), static_cast<double>(c)};
      // Parabolic refinement of the peak along each axis.
      auto refine = [](double left, double mid, double right) {
        const double den = left - 2 * mid + right;
        return den < 0 ? std::clamp(0.5 * (left - right) / den, -0.5, 0.5) : 0.0;
      };
      if (c > 0 && c + 1 < cols) cand.sub_col += refine(s[c - 1], s[c], s[c + 1]);
      if (r > 0 && r + 1 < rows) {
        cand.sub_row += refine(valid.at<float>(r - 1, c), s[c], valid.at<float>(r + 1, c));
      }
      out->push_back(cand);
    }
  }
}

}  // namespace

// VictimDetector(params), with the shipped model, is defined in shipped_model.cpp (its own library,
// so that the trainer links the detector without a model).
VictimDetector::VictimDetector(std::shared_ptr<const VictimDetectorModel> model,
                               const VictimDetectorParams& params)
    : model_(std::move(model)), params_(params), patches_(model_ ? model_->cnn_patch_px : kCnnPatchPx) {
  SWARMBOX_CHECK(model_ && (model_->forest || model_->has_cnn()) && static_cast<int>(model_->kernels.size()) == kChannels);
  SWARMBOX_CHECK(params_.max_candidates > 0 && params_.nms_radius_m >= 0);
  if (model_->has_cnn()) {
    // The bytes were checked when the model was trained and loaded: a network that does not parse
    // here is a broken build, not a runtime condition.
    cnn_ = cv::dnn::readNetFromONNX(reinterpret_cast<const char*>(model_->cnn_onnx.data()), model_->cnn_onnx.size());
    SWARMBOX_CHECK(!cnn_.empty());
    cnn_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
    cnn_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  }
  if (model_->has_close_cnn()) {
    SWARMBOX_CHECK(model_->close_px_per_m > 0);
    close_ =
        std::make_unique<VictimDetector>(std::make_shared<VictimDetectorModel>(model_->CloseView()), params_);
  }
  candidates_.reserve(static_cast<std::size_t>(params_.max_candidates) * 4);
  scratch_.reserve(static_cast<std::size_t>(params_.max_candidates));
  kept_.reserve(static_cast<std::size_t>(params_.max_candidates));
  scores_.reserve(static_cast<std::size_t>(params_.max_candidates));
}

const std::vector<VictimDetector::Candidate>& VictimDetector::Candidates(const cv::Mat& bgr, double pixels_per_m,
                                                                         int max_candidates, double threshold) {
  SWARMBOX_CHECK(bgr.type() == CV_8UC3 && pixels_per_m > 0);
  candidates_.clear();
  frame_ = bgr;
  frame_px_per_m_ = pixels_per_m;
  patch_frame_set_ = false;
  scale_ = kCanonicalPxPerM / pixels_per_m;
  ComputeChannels(bgr, scale_, &maps_);
  if (model_->blob_features > 0) blob_.SetFrame(bgr, pixels_per_m);
  const int rows = maps_.rows() - kWindowCells + 1, cols = maps_.cols() - kWindowCells + 1;
  if (rows <= 0 || cols <= 0) return candidates_;
  score_.create(maps_.rows(), maps_.cols(), CV_32F);
  score_.setTo(cv::Scalar(model_->bias));
  for (int c = 0; c < kChannels; ++c) {
    cv::filter2D(maps_.cells[static_cast<std::size_t>(c)], filtered_, CV_32F, model_->kernels[static_cast<std::size_t>(c)],
                 cv::Point(0, 0), 0, cv::BORDER_CONSTANT);
    score_ += filtered_;
  }
  const cv::Mat valid = score_(cv::Rect(0, 0, cols, rows));
  const int reach =
      std::max(1, static_cast<int>(std::lround(params_.candidate_spacing_m * kCanonicalPxPerM / kShrink)));
  const cv::Mat square = cv::Mat::ones(2 * reach + 1, 2 * reach + 1, CV_8U);
  cv::dilate(valid, dilated_, square, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(-1e9));
  LocalMaxima(valid, dilated_, threshold, &candidates_);
  std::sort(candidates_.begin(), candidates_.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  if (static_cast<int>(candidates_.size()) > max_candidates) candidates_.resize(static_cast<std::size_t>(max_candidates));
  return candidates_;
}

Eigen::Vector2d VictimDetector::CentrePx(const Candidate& c) const {
  return {CanonicalToInput(kShrink * (c.sub_col + kWindowCells / 2.0), scale_),
          CanonicalToInput(kShrink * (c.sub_row + kWindowCells / 2.0), scale_)};
}

void VictimDetector::ForestFeatures(const Candidate& c, float* out) {
  WindowFeatures(maps_, c.row, c.col, out);
  out[kWindowFeatures] = static_cast<float>(c.score);
  if (model_->blob_features > 0) blob_.Extract(CentrePx(c), out + kForestFeatures);
}

void VictimDetector::CnnPatch(const Candidate& c, cv::Mat* patch) {
  SWARMBOX_CHECK(!frame_.empty());
  if (!patch_frame_set_) {
    patches_.SetFrame(frame_, frame_px_per_m_);
    patch_frame_set_ = true;
  }
  patches_.Extract(CentrePx(c), patch);
}

namespace {

// Symmetry k (1-7) of the square applied to `patch`: turned k % 4 times by 90 degrees clockwise,
// then mirrored left-right when k >= 4.
void SquareSymmetry(const cv::Mat& patch, int k, cv::Mat* out) {
  static constexpr cv::RotateFlags kTurns[] = {cv::ROTATE_90_CLOCKWISE, cv::ROTATE_180,
                                               cv::ROTATE_90_COUNTERCLOCKWISE};
  const int turns = k % 4;
  if (turns == 0) {
    cv::flip(patch, *out, 1);
    return;
  }
  cv::rotate(patch, *out, kTurns[turns - 1]);
  if (k >= 4) cv::flip(*out, *out, 1);
}

}  // namespace

void VictimDetector::CnnScores(const std::vector<Candidate>& cands, const std::vector<int>& kept,
                               std::vector<double>* scores) {
  // Each candidate's patch, then its other cnn_symmetries - 1 symmetries, in one batch.
  const auto views = static_cast<std::size_t>(model_->cnn_symmetries);
  patch_batch_.resize(kept.size() * views);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    cv::Mat* first = &patch_batch_[i * views];
    CnnPatch(cands[static_cast<std::size_t>(kept[i])], first);
    for (std::size_t k = 1; k < views; ++k) SquareSymmetry(*first, static_cast<int>(k), first + k);
  }
  // (pixel - kCnnInputMean) * kCnnInputScale, N x 3 x H x W, BGR as sampled (train_cnn.py reads the
  // trainer's patches in the same order).
  cv::dnn::blobFromImages(patch_batch_, cnn_input_, kCnnInputScale,
                          cv::Size(patches_.patch_px(), patches_.patch_px()), cv::Scalar::all(kCnnInputMean),
                          false, false, CV_32F);
  cnn_.setInput(cnn_input_);
  cnn_output_ = cnn_.forward();
  SWARMBOX_CHECK(cnn_output_.total() == patch_batch_.size() && cnn_output_.type() == CV_32F);
  const float* logits = cnn_output_.ptr<float>();
  scores->clear();
  for (std::size_t i = 0; i < kept.size(); ++i) {
    double sum = 0;
    for (std::size_t k = 0; k < views; ++k) sum += logits[i * views + k];
    scores->push_back(sum / static_cast<double>(views));
  }
}

void VictimDetector::Detect(const cv::Mat& bgr, double pixels_per_m, std::vector<ImageBlob>* out) {
  DetectImpl(bgr, pixels_per_m, [](const Eigen::Vector2d&) { return true; }, out);
}

void VictimDetector::Detect(const cv::Mat& bgr, const PinholeIntrinsics& k, const OpticalPose& pose,
                            double ground_z_m, std::vector<ImageBlob>* out) {
  SWARMBOX_CHECK(k.fx_px > 0 && k.fy_px > 0);
  out->clear();
  const std::optional<Eigen::Vector3d> centre = PixelToGround({k.cx_px, k.cy_px}, k, pose, ground_z_m);
  double range_m = 0;
  if (centre) {
    const Eigen::Vector3d axis = pose.rotation * Eigen::Vector3d::UnitZ();
    range_m = (*centre - pose.position_m).dot(axis);
  } else {
    // The optical axis misses the ground: scale from the height (the nearest ground is below).
    range_m = pose.position_m.z() - ground_z_m;
  }
  if (!(range_m > 0.1)) return;
  DetectImpl(
      bgr, k.fx_px / range_m,
      [&](const Eigen::Vector2d& px) { return PixelToGround(px, k, pose, ground_z_m).has_value(); }, out);
}

void VictimDetector::SecondStageScores(const std::vector<Candidate>& cands) {
  if (model_->has_cnn()) {
    CnnScores(cands, kept_, &scores_);
    return;
  }
  samples_.resize(static_cast<std::size_t>(model_->forest_inputs()));
  scores_.clear();
  for (int i : kept_) {
    ForestFeatures(cands[static_cast<std::size_t>(i)], samples_.data());
    scores_.push_back(model_->Votes(samples_.data()));
  }
}

template <typename KeepFn>
void VictimDetector::DetectImpl(const cv::Mat& bgr, double pixels_per_m, KeepFn keep, std::vector<ImageBlob>* out) {
  SWARMBOX_CHECK(bgr.type() == CV_8UC3);
  SWARMBOX_CHECK(pixels_per_m > 0);
  if (close_ && pixels_per_m >= model_->close_px_per_m) {  // the close look's CNN and sigmoid
    close_->DetectImpl(bgr, pixels_per_m, keep, out);
    return;
  }
  out->clear();
  const std::vector<Candidate>& cands = Candidates(bgr, pixels_per_m, params_.max_candidates, model_->stage1_threshold);
  if (cands.empty()) return;
  kept_.clear();
  for (std::size_t i = 0; i < cands.size(); ++i) {
    const Eigen::Vector2d px = CentrePx(cands[i]);
    if (px.x() < -0.5 || px.y() < -0.5 || px.x() > bgr.cols - 0.5 || px.y() > bgr.rows - 0.5) continue;  // off the image
    if (keep(px)) kept_.push_back(static_cast<int>(i));
  }
  if (kept_.empty()) return;
  SecondStageScores(cands);
  const double expected_area = params_.person_area_m2 * pixels_per_m * pixels_per_m;
  const double half_px = params_.partial_half_extent_m * pixels_per_m;
  scratch_.clear();
  for (std::size_t k = 0; k < kept_.size(); ++k) {
    const Candidate& c = cands[static_cast<std::size_t>(kept_[k])];
    ImageBlob b;
    b.centroid_px = CentrePx(c);
    const double u = b.centroid_px.x(), v = b.centroid_px.y();
    b.votes = scores_[k];
    b.confidence = model_->Probability(b.votes, pixels_per_m);
    if (b.confidence < params_.min_confidence) continue;
    b.linear_score = c.score;
    b.expected_area_px = expected_area;
    b.area_px = expected_area;
    b.partial = u < half_px || v < half_px || u > bgr.cols - half_px || v > bgr.rows - half_px;
    if (b.partial) b.confidence = std::min(b.confidence, params_.partial_confidence_cap);
    scratch_.push_back(b);
  }
  SuppressNonMaxima(&scratch_, params_.nms_radius_m * pixels_per_m, out);
}

}  // namespace swarmbox::swarm
