#include "swarmbox/swarm/victim_detector_model.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <opencv2/imgproc.hpp>

#include "swarmbox/swarm/blob_features.hpp"
#include "swarmbox/swarm/candidate_patch.hpp"

namespace swarmbox::swarm {
namespace {

constexpr int kCellsPerWindow = kWindowCells * kWindowCells;
// 2: the blob features after the window features and score (blob_features), and the recipe.
constexpr int kFormatVersion = 2;
constexpr int kWindowOnlyFormatVersion = 1;
// 3: a convolutional second stage (cnn_onnx, its patch layout) in place of the forest.
constexpr int kCnnFormatVersion = 3;

}  // namespace

void ComputeChannels(const cv::Mat& bgr, double scale, ChannelMaps* m) {
  SWARMBOX_CHECK(bgr.type() == CV_8UC3 && scale > 0);
  const int w = std::max(kShrink, static_cast<int>(std::lround(bgr.cols * scale)));
  const int h = std::max(kShrink, static_cast<int>(std::lround(bgr.rows * scale)));
  cv::resize(bgr, m->canonical, cv::Size(w, h), 0, 0, scale < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR);
  const int pad = kPadCells * kShrink;
  cv::copyMakeBorder(m->canonical, m->padded, pad, pad, pad, pad, cv::BORDER_REPLICATE);
  // Whole cells only.
  const int pw = m->padded.cols / kShrink * kShrink, ph = m->padded.rows / kShrink * kShrink;
  const cv::Mat img = m->padded(cv::Rect(0, 0, pw, ph));
  cv::cvtColor(img, m->luv, cv::COLOR_BGR2Luv);
  m->full.resize(kChannels);
  cv::Mat luv_f;
  m->luv.convertTo(luv_f, CV_32FC3, 1.0 / 255);
  cv::split(luv_f, &m->full[0]);  // first three maps: L, u, v
  m->l = m->full[0];
  cv::Sobel(m->l, m->gx, CV_32F, 1, 0, 3, 0.25);
  cv::Sobel(m->l, m->gy, CV_32F, 0, 1, 3, 0.25);
  cv::cartToPolar(m->gx, m->gy, m->mag, m->angle, false);
  m->full[kColourChannels] = m->mag;
  for (int o = 0; o < kOrientations; ++o) m->full[static_cast<std::size_t>(kColourChannels + 1 + o)].create(ph, pw, CV_32F);
  for (int r = 0; r < ph; ++r) {
    const float* mag = m->mag.ptr<float>(r);
    const float* ang = m->angle.ptr<float>(r);
    float* o[kOrientations];
    for (int k = 0; k < kOrientations; ++k) o[k] = m->full[static_cast<std::size_t>(kColourChannels + 1 + k)].ptr<float>(r);
    for (int c = 0; c < pw; ++c) {
      // Unsigned orientation in [0, pi): bins of pi / kOrientations.
      float a = ang[c];
      if (a >= static_cast<float>(CV_PI)) a -= static_cast<float>(CV_PI);
      const int bin = std::min(kOrientations - 1, static_cast<int>(a * (kOrientations / static_cast<float>(CV_PI))));
      for (int k = 0; k < kOrientations; ++k) o[k][c] = k == bin ? mag[c] : 0.0f;
    }
  }
  m->cells.resize(kChannels);
  for (int c = 0; c < kChannels; ++c) {
    cv::resize(m->full[static_cast<std::size_t>(c)], m->cells[static_cast<std::size_t>(c)],
               cv::Size(pw / kShrink, ph / kShrink), 0, 0, cv::INTER_AREA);
  }
}

void WindowFeatures(const ChannelMaps& m, int row, int col, float* out) {
  SWARMBOX_CHECK(row >= 0 && col >= 0 && row + kWindowCells <= m.rows() && col + kWindowCells <= m.cols());
  float* means = out + kChannels * kCellsPerWindow;
  for (int c = 0; c < kChannels; ++c) {
    const cv::Mat& map = m.cells[static_cast<std::size_t>(c)];
    float* dst = out + c * kCellsPerWindow;
    double sum = 0;
    for (int i = 0; i < kWindowCells; ++i) {
      const float* src = map.ptr<float>(row + i) + col;
      for (int j = 0; j < kWindowCells; ++j) {
        dst[i * kWindowCells + j] = src[j];
        sum += src[j];
      }
    }
    if (c < kColourChannels) {
      const auto mean = static_cast<float>(sum / kCellsPerWindow);
      for (int k = 0; k < kCellsPerWindow; ++k) dst[k] -= mean;
      means[c] = mean;
    }
  }
}

void VictimDetectorModel::SetLinear(const std::vector<double>& weights, double b) {
  SWARMBOX_CHECK(weights.size() == static_cast<std::size_t>(kWindowFeatures));
  // Colour cells enter as (x_i - mean), the mean with weight u: sum_i w_i x_i - (sum_i w_i) mean +
  // u mean = sum_i (w_i - W/N + u/N) x_i. One kernel per channel.
  kernels.assign(kChannels, cv::Mat());
  for (int c = 0; c < kChannels; ++c) {
    cv::Mat k(kWindowCells, kWindowCells, CV_32F);
    double offset = 0;
    if (c < kColourChannels) {
      double total = 0;
      for (int i = 0; i < kCellsPerWindow; ++i) total += weights[static_cast<std::size_t>(c * kCellsPerWindow + i)];
      offset = (-total + weights[static_cast<std::size_t>(kChannels * kCellsPerWindow + c)]) / kCellsPerWindow;
    }
    for (int i = 0; i < kCellsPerWindow; ++i) {
      k.at<float>(i / kWindowCells, i % kWindowCells) =
          static_cast<float>(weights[static_cast<std::size_t>(c * kCellsPerWindow + i)] + offset);
    }
    kernels[static_cast<std::size_t>(c)] = k;
  }
  bias = b;
}

double VictimDetectorModel::LinearScore(const float* f) const {
  // Undo the mean subtraction: the kernels act on the raw cells.
  double s = bias;
  for (int c = 0; c < kChannels; ++c) {
    const float* k = kernels[static_cast<std::size_t>(c)].ptr<float>(0);
    const float* x = f + c * kCellsPerWindow;
    const double mean = c < kColourChannels ? f[kChannels * kCellsPerWindow + c] : 0.0;
    for (int i = 0; i < kCellsPerWindow; ++i) s += k[i] * (x[i] + mean);
  }
  return s;
}

void VictimDetectorModel::FlattenForest() {
  SWARMBOX_CHECK(forest && forest->isTrained());
  const std::vector<cv::ml::DTrees::Node>& src = forest->getNodes();
  const std::vector<cv::ml::DTrees::Split>& splits = forest->getSplits();
  nodes.assign(src.size(), ForestNode{});
  for (std::size_t i = 0; i < src.size(); ++i) {
    const cv::ml::DTrees::Node& n = src[i];
    ForestNode& d = nodes[i];
    if (n.split < 0) {
      d.person = n.value == 1.0 ? 1.0f : 0.0f;
      continue;
    }
    const cv::ml::DTrees::Split& sp = splits[static_cast<std::size_t>(n.split)];
    d.var = sp.varIdx;
    d.threshold = sp.c;
    d.left = sp.inversed ? n.right : n.left;
    d.right = sp.inversed ? n.left : n.right;
  }
  roots = forest->getRoots();
}

double VictimDetectorModel::Votes(const float* x) const {
  if (roots.empty()) return 0.0;
  double person = 0;
  for (int r : roots) {
    const ForestNode* n = &nodes[static_cast<std::size_t>(r)];
    while (n->var >= 0) n = &nodes[static_cast<std::size_t>(x[n->var] <= n->threshold ? n->left : n->right)];
    person += n->person;
  }
  return person / static_cast<double>(roots.size());
}

namespace {

// Platt's sigmoid: 1 / (1 + exp(a votes + b)).
double Platt(double a, double b, double votes) { return 1.0 / (1.0 + std::exp(a * votes + b)); }

}  // namespace

double VictimDetectorModel::Probability(double votes) const { return Platt(platt_a, platt_b, votes); }

VictimDetectorModel VictimDetectorModel::CloseView() const {
  VictimDetectorModel close = *this;
  close.cnn_onnx = close_cnn_onnx;
  close.cnn_patch_px = close_cnn_patch_px;
  close.platt_a = close_platt_a;
  close.platt_b = close_platt_b;
  close.close_px_per_m = 0;
  close.close_cnn_onnx.clear();
  close.close_cnn_patch_px = 0;
  return close;
}

double VictimDetectorModel::Probability(double votes, double pixels_per_m) const {
  const bool close = close_px_per_m > 0 && pixels_per_m >= close_px_per_m;
  return close ? Platt(close_platt_a, close_platt_b, votes) : Probability(votes);
}

namespace {

// The second stage into fs: the forest, or the CNN's ONNX bytes and its patch layout.
void WriteSecondStage(const VictimDetectorModel& model, cv::FileStorage& fs) {
  if (model.has_cnn()) {
    fs << "cnn_patch_px" << model.cnn_patch_px << "cnn_patch_m" << kCnnPatchM << "cnn_input_mean"
       << kCnnInputMean << "cnn_input_scale" << kCnnInputScale;
    if (model.cnn_symmetries != 1) fs << "cnn_symmetries" << model.cnn_symmetries;
    fs << "cnn_onnx" << cv::Mat(1, static_cast<int>(model.cnn_onnx.size()), CV_8U,
                                const_cast<std::uint8_t*>(model.cnn_onnx.data()));
    if (model.has_close_cnn()) {
      fs << "close_cnn_patch_px" << model.close_cnn_patch_px;
      fs << "close_cnn_onnx"
         << cv::Mat(1, static_cast<int>(model.close_cnn_onnx.size()), CV_8U,
                    const_cast<std::uint8_t*>(model.close_cnn_onnx.data()));
    }
    return;
  }
  fs << "forest" << "{";
  model.forest->write(fs);
  fs << "}";
}

}  // namespace

Status SaveDetectorModel(const VictimDetectorModel& model, const std::string& path) {
  SWARMBOX_CHECK((model.forest || model.has_cnn()) && static_cast<int>(model.kernels.size()) == kChannels);
  try {
    cv::FileStorage fs(path, cv::FileStorage::WRITE);
    if (!fs.isOpened()) return Error(ErrorCode::kIo, "cannot write the detector model", path);
    // A window-only model keeps format 1's layout, so the default training step still writes the
    // shipped file (agent/swarm/models) as before the blob features.
    const bool blob = model.blob_features != 0 || model.has_cnn();
    fs << "format_version"
       << (model.has_cnn() ? kCnnFormatVersion : model.blob_features != 0 ? kFormatVersion : kWindowOnlyFormatVersion);
    fs << "canonical_px_per_m" << kCanonicalPxPerM << "shrink" << kShrink << "window_cells" << kWindowCells
       << "channels" << kChannels;
    fs << "bias" << model.bias << "stage1_threshold" << model.stage1_threshold;
    fs << "platt_a" << model.platt_a << "platt_b" << model.platt_b;
    if (model.close_px_per_m > 0) {
      fs << "close_px_per_m" << model.close_px_per_m << "close_platt_a" << model.close_platt_a
         << "close_platt_b" << model.close_platt_b;
    }
    std::vector<double> seeds(model.training_seeds.begin(), model.training_seeds.end());
    std::vector<double> cal(model.calibration_seeds.begin(), model.calibration_seeds.end());
    fs << "training_seeds" << seeds << "calibration_seeds" << cal;
    if (blob) fs << "blob_features" << model.blob_features << "recipe" << model.recipe;
    fs << "kernels" << "[";
    for (const cv::Mat& k : model.kernels) fs << k;
    fs << "]";
    WriteSecondStage(model, fs);
  } catch (const cv::Exception& e) {
    return Error(ErrorCode::kIo, std::string("writing the detector model: ") + e.what(), path);
  }
  return Ok{};
}

namespace {

// The layout the file was written for (format, scale, cells, channels, blob features) into *m,
// or the reason it is not this build's.
Status ReadLayout(cv::FileStorage& fs, const std::string& where, VictimDetectorModel* m) {
  const int version = static_cast<int>(fs["format_version"]);
  if ((version != kFormatVersion && version != kWindowOnlyFormatVersion && version != kCnnFormatVersion) ||
      static_cast<double>(fs["canonical_px_per_m"]) != kCanonicalPxPerM ||
      static_cast<int>(fs["shrink"]) != kShrink || static_cast<int>(fs["window_cells"]) != kWindowCells ||
      static_cast<int>(fs["channels"]) != kChannels) {
    return Error(ErrorCode::kInvalidArgument,
                 "detector model: another format or feature layout than this build (retrain: target train-detector)",
                 where);
  }
  if (version == kCnnFormatVersion && (!ValidCnnPatchPx(static_cast<int>(fs["cnn_patch_px"])) ||
                                       static_cast<double>(fs["cnn_patch_m"]) != kCnnPatchM ||
                                       static_cast<double>(fs["cnn_input_mean"]) != kCnnInputMean ||
                                       static_cast<double>(fs["cnn_input_scale"]) != kCnnInputScale)) {
    return Error(ErrorCode::kInvalidArgument,
                 "detector model: another CNN patch layout than this build (retrain: target train-detector)", where);
  }
  if (version == kCnnFormatVersion) {
    m->cnn_patch_px = static_cast<int>(fs["cnn_patch_px"]);
    // Optional: a model written before test-time augmentation scores each patch once.
    m->cnn_symmetries = fs["cnn_symmetries"].empty() ? 1 : static_cast<int>(fs["cnn_symmetries"]);
    if (!ValidCnnSymmetries(m->cnn_symmetries)) {
      return Error(ErrorCode::kInvalidArgument, "detector model: cnn_symmetries must be 1, 4 or 8", where);
    }
  }
  if (version == kFormatVersion || version == kCnnFormatVersion) {
    m->blob_features = static_cast<int>(fs["blob_features"]);
    m->recipe = static_cast<std::string>(fs["recipe"]);
  }
  if (m->blob_features != 0 && m->blob_features != kBlobFeatures) {
    return Error(ErrorCode::kInvalidArgument,
                 "detector model: another blob feature layout than this build (retrain: target train-detector)", where);
  }
  return Ok{};
}

// The first stage's kernels into *m.
Status ReadKernels(cv::FileStorage& fs, const std::string& where, VictimDetectorModel* m) {
  const cv::FileNode kernels = fs["kernels"];
  for (auto it = kernels.begin(); it != kernels.end(); ++it) {
    cv::Mat k;
    (*it) >> k;
    if (k.rows != kWindowCells || k.cols != kWindowCells || k.type() != CV_32F) {
      return Error(ErrorCode::kInvalidArgument, "detector model: a first-stage kernel of the wrong shape", where);
    }
    m->kernels.push_back(k);
  }
  if (static_cast<int>(m->kernels.size()) != kChannels) {
    return Error(ErrorCode::kInvalidArgument, "detector model: wrong number of first-stage kernels", where);
  }
  return Ok{};
}

// The ONNX bytes under `key` into *bytes.
Status ReadOnnx(cv::FileStorage& fs, const char* key, const std::string& where,
                std::vector<std::uint8_t>* bytes) {
  cv::Mat onnx;
  fs[key] >> onnx;
  if (onnx.empty() || onnx.type() != CV_8U || !onnx.isContinuous()) {
    return Error(ErrorCode::kInvalidArgument, std::string("detector model: ") + key + " is not a byte row",
                 where);
  }
  bytes->assign(onnx.ptr<std::uint8_t>(0), onnx.ptr<std::uint8_t>(0) + onnx.total());
  return Ok{};
}

// The forest (flattened), or the CNN's ONNX bytes (and the close look's, optional) when the file
// has them, into *m.
Status ReadSecondStage(cv::FileStorage& fs, const std::string& where, VictimDetectorModel* m) {
  if (!fs["cnn_onnx"].empty()) {
    SWARMBOX_TRY(ReadOnnx(fs, "cnn_onnx", where, &m->cnn_onnx));
    if (fs["close_cnn_onnx"].empty()) return Ok{};
    m->close_cnn_patch_px = static_cast<int>(fs["close_cnn_patch_px"]);
    if (!ValidCnnPatchPx(m->close_cnn_patch_px) || m->close_px_per_m <= 0) {
      return Error(ErrorCode::kInvalidArgument,
                   "detector model: a close-look CNN needs a valid close_cnn_patch_px and close_px_per_m",
                   where);
    }
    return ReadOnnx(fs, "close_cnn_onnx", where, &m->close_cnn_onnx);
  }
  m->forest = cv::ml::RTrees::create();
  m->forest->read(fs["forest"]);
  if (!m->forest->isTrained() || m->forest->getVarCount() != m->forest_inputs()) {
    return Error(ErrorCode::kInvalidArgument, "detector model: the forest is missing or has the wrong inputs", where);
  }
  m->FlattenForest();
  return Ok{};
}

Result<std::shared_ptr<const VictimDetectorModel>> Read(cv::FileStorage& fs, const std::string& where) {
  auto m = std::make_shared<VictimDetectorModel>();
  SWARMBOX_TRY(ReadLayout(fs, where, m.get()));
  m->bias = static_cast<double>(fs["bias"]);
  m->stage1_threshold = static_cast<double>(fs["stage1_threshold"]);
  m->platt_a = static_cast<double>(fs["platt_a"]);
  m->platt_b = static_cast<double>(fs["platt_b"]);
  if (!fs["close_px_per_m"].empty()) {  // optional: a model with one sigmoid has none
    m->close_px_per_m = static_cast<double>(fs["close_px_per_m"]);
    m->close_platt_a = static_cast<double>(fs["close_platt_a"]);
    m->close_platt_b = static_cast<double>(fs["close_platt_b"]);
  }
  std::vector<double> seeds, cal;
  fs["training_seeds"] >> seeds;
  fs["calibration_seeds"] >> cal;
  for (double s : seeds) m->training_seeds.push_back(static_cast<std::uint64_t>(s));
  for (double s : cal) m->calibration_seeds.push_back(static_cast<std::uint64_t>(s));
  SWARMBOX_TRY(ReadKernels(fs, where, m.get()));
  SWARMBOX_TRY(ReadSecondStage(fs, where, m.get()));
  return std::shared_ptr<const VictimDetectorModel>(std::move(m));
}

}  // namespace

Result<std::shared_ptr<const VictimDetectorModel>> LoadDetectorModel(const std::string& path) {
  try {
    cv::FileStorage fs(path, cv::FileStorage::READ);
    if (!fs.isOpened()) return Error(ErrorCode::kNotFound, "cannot read the detector model", path);
    return Read(fs, path);
  } catch (const cv::Exception& e) {
    return Error(ErrorCode::kInvalidArgument, std::string("reading the detector model: ") + e.what(), path);
  }
}

Result<std::shared_ptr<const VictimDetectorModel>> LoadDetectorModelFromText(const std::string& yaml) {
  try {
    cv::FileStorage fs(yaml, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    if (!fs.isOpened()) return Error(ErrorCode::kInvalidArgument, "the detector model text does not parse");
    return Read(fs, "compiled-in model");
  } catch (const cv::Exception& e) {
    return Error(ErrorCode::kInvalidArgument, std::string("reading the detector model: ") + e.what());
  }
}

Result<std::string> GunzipText(const unsigned char* data, std::size_t size) {
  z_stream zs{};
  if (inflateInit2(&zs, 16 + MAX_WBITS) != Z_OK) return Error(ErrorCode::kInternal, "inflateInit2 failed");
  zs.next_in = const_cast<unsigned char*>(data);
  zs.avail_in = static_cast<uInt>(size);
  std::string out;
  char buf[1 << 16];
  int rc = Z_OK;
  while (rc == Z_OK) {
    zs.next_out = reinterpret_cast<unsigned char*>(buf);
    zs.avail_out = sizeof(buf);
    rc = inflate(&zs, Z_NO_FLUSH);
    out.append(buf, sizeof(buf) - zs.avail_out);
  }
  inflateEnd(&zs);
  if (rc != Z_STREAM_END) return Error(ErrorCode::kInvalidArgument, "the compiled-in model is not valid gzip");
  return out;
}

}  // namespace swarmbox::swarm
