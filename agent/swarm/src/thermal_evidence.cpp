#include "swarmbox/swarm/thermal_evidence.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace swarmbox::swarm {

namespace {

float Quantile(std::vector<float>& v, double q) {
  const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<std::size_t>(k)];
}

}  // namespace

std::optional<double> ThermalContrastAt(const ThermalView& view, const Eigen::Vector3d& point_m,
                                        double radius_m) {
  if (view.kelvin.empty() || view.kelvin.type() != CV_32F || !(radius_m > 0)) return std::nullopt;
  const std::optional<Eigen::Vector2d> px = ProjectToPixel(point_m, view.k, view.pose);
  if (!px) return std::nullopt;
  const double range = (point_m - view.pose.position_m).norm();
  const double r_px = radius_m * view.k.fx_px / std::max(range, 1e-3);
  if (r_px < 0.5) return std::nullopt;
  const double outer = 3.4 * r_px, inner = 1.7 * r_px;
  const int x0 = static_cast<int>(std::floor(px->x() - outer)),
            x1 = static_cast<int>(std::ceil(px->x() + outer));
  const int y0 = static_cast<int>(std::floor(px->y() - outer)),
            y1 = static_cast<int>(std::ceil(px->y() + outer));
  if (x0 < 0 || y0 < 0 || x1 >= view.kelvin.cols || y1 >= view.kelvin.rows) return std::nullopt;
  std::vector<float> disc, ring;
  for (int y = y0; y <= y1; ++y) {
    const float* row = view.kelvin.ptr<float>(y);
    for (int x = x0; x <= x1; ++x) {
      const double d = std::hypot(x + 0.5 - px->x(), y + 0.5 - px->y());
      if (d <= r_px) {
        disc.push_back(row[x]);
      } else if (d >= inner && d <= outer) {
        ring.push_back(row[x]);
      }
    }
  }
  if (disc.empty() || ring.size() < 8) return std::nullopt;
  return static_cast<double>(Quantile(disc, 0.98)) - static_cast<double>(Quantile(ring, 0.5));
}

bool ThermalPatchAt(const ThermalView& view, const Eigen::Vector3d& point_m, cv::Mat* patch) {
  if (view.kelvin.empty() || view.kelvin.type() != CV_32F) return false;
  cv::Mat map_x(kThermalPatchPx, kThermalPatchPx, CV_32F), map_y(kThermalPatchPx, kThermalPatchPx, CV_32F);
  const double half = (kThermalPatchPx - 1) / 2.0;
  for (int r = 0; r < kThermalPatchPx; ++r) {
    for (int c = 0; c < kThermalPatchPx; ++c) {
      const Eigen::Vector3d q =
          point_m + Eigen::Vector3d((c - half) * kThermalPatchM, (half - r) * kThermalPatchM, 0);
      const std::optional<Eigen::Vector2d> px = ProjectToPixel(q, view.k, view.pose);
      // Pixel (x, y) covers [x, x + 1): its centre, where cv::remap samples it, is x + 0.5.
      if (!px || px->x() < 0.5 || px->y() < 0.5 || px->x() > view.kelvin.cols - 0.5 ||
          px->y() > view.kelvin.rows - 0.5)
        return false;
      map_x.at<float>(r, c) = static_cast<float>(px->x() - 0.5);
      map_y.at<float>(r, c) = static_cast<float>(px->y() - 0.5);
    }
  }
  cv::Mat k;
  cv::remap(view.kelvin, k, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  std::vector<float> all(k.begin<float>(), k.end<float>());
  const float median = Quantile(all, 0.5);
  k.convertTo(*patch, CV_32F, 1.0 / kThermalPatchScaleK, -median / kThermalPatchScaleK);
  cv::min(*patch, kThermalPatchMax, *patch);
  cv::max(*patch, kThermalPatchMin, *patch);
  return true;
}

Result<std::unique_ptr<ThermalClassifier>> ThermalClassifier::FromOnnx(std::string_view onnx) {
  std::unique_ptr<ThermalClassifier> c(new ThermalClassifier());
  try {
    c->net_ = cv::dnn::readNetFromONNX(onnx.data(), onnx.size());
  } catch (const cv::Exception& e) {
    return Error(ErrorCode::kInvalidArgument,
                 std::string("thermal classifier: OpenCV cannot read the ONNX: ") + e.what());
  }
  if (c->net_.empty()) return Error(ErrorCode::kInvalidArgument, "thermal classifier: an empty network");
  c->net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  c->net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  const cv::Mat probe = cv::Mat::zeros(kThermalPatchPx, kThermalPatchPx, CV_32F);
  try {
    (void)c->Logit(probe);
  } catch (const cv::Exception& e) {
    return Error(ErrorCode::kInvalidArgument,
                 std::string("thermal classifier: the network does not take a patch: ") + e.what());
  }
  return c;
}

double ThermalClassifier::Logit(const cv::Mat& patch) {
  SWARMBOX_CHECK(patch.type() == CV_32F && patch.rows == kThermalPatchPx && patch.cols == kThermalPatchPx);
  static constexpr cv::RotateFlags kTurns[] = {cv::ROTATE_90_CLOCKWISE, cv::ROTATE_180,
                                               cv::ROTATE_90_COUNTERCLOCKWISE};
  views_.resize(8);
  views_[0] = patch;
  for (int t = 1; t < 4; ++t) cv::rotate(patch, views_[static_cast<std::size_t>(t)], kTurns[t - 1]);
  for (std::size_t t = 0; t < 4; ++t) cv::flip(views_[t], views_[t + 4], 1);
  cv::dnn::blobFromImages(views_, input_, 1.0, cv::Size(), cv::Scalar(), false, false, CV_32F);
  net_.setInput(input_);
  const cv::Mat out = net_.forward();
  if (out.total() != views_.size())
    throw cv::Exception(cv::Error::StsBadSize, "one logit a patch expected", "ThermalClassifier::Logit",
                        __FILE__, __LINE__);
  const float* logits = out.ptr<float>();
  double sum = 0;
  for (std::size_t i = 0; i < views_.size(); ++i) sum += logits[i];
  return sum / static_cast<double>(views_.size());
}

double ThermalEvidence::Fuse(double confidence, double contrast_k, double cnn_logit) const {
  const double p = std::clamp(confidence, 1e-6, 1 - 1e-6);
  const double z = colour_weight * std::log(p / (1 - p)) +
                   slope_per_k * std::clamp(contrast_k, kMinContrastK, kMaxContrastK) +
                   cnn_weight * std::clamp(cnn_logit, -kMaxCnnLogit, kMaxCnnLogit) + bias;
  return 1.0 / (1.0 + std::exp(-z));
}

ThermalFusion::ThermalFusion(const ThermalEvidence& evidence) : evidence_(evidence) {
  if (evidence_.cnn_weight <= 0) return;
  Result<std::unique_ptr<ThermalClassifier>> c =
      evidence_.cnn_onnx != nullptr
          ? ThermalClassifier::FromOnnx(*evidence_.cnn_onnx)
          : Result<std::unique_ptr<ThermalClassifier>>(
                Error(ErrorCode::kInvalidArgument, "thermal evidence: a cnn_weight without its network"));
  if (!c) {
    std::fprintf(stderr, "swarmbox: fatal: %s\n", c.error().ToString().c_str());
    std::abort();
  }
  classifier_ = std::move(*c);
}

double ThermalFusion::Apply(double confidence, const ThermalView& view, const Eigen::Vector3d& point_m) {
  const std::optional<double> c = ThermalContrastAt(view, point_m, evidence_.radius_m);
  if (!c) return confidence;
  const double logit =
      classifier_ != nullptr && ThermalPatchAt(view, point_m, &patch_) ? classifier_->Logit(patch_) : 0.0;
  return evidence_.Fuse(confidence, *c, logit);
}

Result<ThermalEvidence> ParseThermalEvidence(const yaml::Node& root) {
  const yaml::Node* n = root.Find("thermal_evidence");
  if (n == nullptr)
    return Error(ErrorCode::kInvalidArgument, "thermal evidence: no `thermal_evidence:` mapping",
                 root.Where());
  ThermalEvidence e;
  yaml::MapReader r(*n, "thermal_evidence");
  r.Required("colour_weight", &e.colour_weight)
      .Required("slope_per_k", &e.slope_per_k)
      .Required("bias", &e.bias)
      .Required("radius_m", &e.radius_m)
      .Optional("cnn_weight", &e.cnn_weight);
  r.Optional("cnn_model", &e.cnn_model);
  (void)r.Child("fit");  // provenance: seeds, counts, figures (read past)
  if (auto s = r.Finish(); !s) return s.error();
  if (!(e.slope_per_k >= 0 && e.slope_per_k < 5)) {
    return Error(ErrorCode::kInvalidArgument, "thermal evidence: slope_per_k must be within 0..5",
                 n->Where());
  }
  if (!(e.radius_m > 0.1 && e.radius_m < 3)) {
    return Error(ErrorCode::kInvalidArgument, "thermal evidence: radius_m must be within 0.1..3", n->Where());
  }
  // With a classifier the colour confidence may add nothing (weight 0); without one it must count.
  if (!(e.colour_weight >= 0 && e.colour_weight < 5) || !(e.colour_weight > 0 || e.cnn_weight > 0) ||
      !(std::abs(e.bias) < 20)) {
    return Error(
        ErrorCode::kInvalidArgument,
        "thermal evidence: colour_weight must be within 0..5 (0 only with a classifier) and |bias| below 20",
        n->Where());
  }
  if (!(e.cnn_weight >= 0 && e.cnn_weight < 5) || (e.cnn_weight > 0) != !e.cnn_model.empty()) {
    return Error(ErrorCode::kInvalidArgument,
                 "thermal evidence: cnn_weight must be within 0..5, and above 0 exactly when cnn_model names "
                 "the network",
                 n->Where());
  }
  return e;
}

}  // namespace swarmbox::swarm
