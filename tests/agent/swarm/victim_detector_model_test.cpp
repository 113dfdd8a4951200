// The shipped detector model (agent/swarm/models/, written by `cmake --build build --target
// train-detector`): it loads, it was trained and calibrated on scene seeds the evaluation never
// uses, the binary carries the same model as the committed file; a forest, flattened as the
// detector runs it, decides as OpenCV's RTrees (the shipped second stage is a CNN).
#include <algorithm>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "perception_scenes.hpp"
#include "swarmbox/swarm/blob_features.hpp"
#include "swarmbox/swarm/victim_detector.hpp"
#include "swarmbox/swarm/victim_detector_model.hpp"

#ifndef SWARMBOX_DETECTOR_MODELS_DIR
#error "SWARMBOX_DETECTOR_MODELS_DIR must point at agent/swarm/models"
#endif

namespace swarmbox::swarm {
namespace {

const std::string kModelDir = SWARMBOX_DETECTOR_MODELS_DIR;

TEST(VictimDetectorModel, TheCommittedModelWasTrainedOnSeedsDisjointFromTheEvaluationSeeds) {
  Result<std::shared_ptr<const VictimDetectorModel>> m = LoadDetectorModel(kModelDir + "/victim_detector.yml.gz");
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  const VictimDetectorModel& model = **m;
  ASSERT_FALSE(model.training_seeds.empty());
  ASSERT_FALSE(model.calibration_seeds.empty());
  for (std::uint64_t e : perception_scenes::kEvaluationSeeds) {
    EXPECT_EQ(std::count(model.training_seeds.begin(), model.training_seeds.end(), e), 0) << e;
    EXPECT_EQ(std::count(model.calibration_seeds.begin(), model.calibration_seeds.end(), e), 0) << e;
  }
  for (std::uint64_t t : model.training_seeds) {
    EXPECT_EQ(std::count(model.calibration_seeds.begin(), model.calibration_seeds.end(), t), 0) << t;
  }
  // The report beside it names the same seeds.
  std::ifstream f(kModelDir + "/victim_detector.json");
  ASSERT_TRUE(f.good());
  std::stringstream json;
  json << f.rdbuf();
  std::ostringstream seeds;
  seeds << "\"training_seeds\": [";
  for (std::size_t i = 0; i < model.training_seeds.size(); ++i) seeds << (i ? ", " : "") << model.training_seeds[i];
  seeds << "]";
  EXPECT_NE(json.str().find(seeds.str()), std::string::npos) << seeds.str();
}

TEST(VictimDetectorModel, TheBinaryCarriesTheCommittedModel) {
  Result<std::shared_ptr<const VictimDetectorModel>> file = LoadDetectorModel(kModelDir + "/victim_detector.yml.gz");
  ASSERT_TRUE(file.ok()) << file.error().ToString();
  const std::shared_ptr<const VictimDetectorModel> shipped = ShippedDetectorModel();
  EXPECT_EQ(shipped->training_seeds, (*file)->training_seeds);
  EXPECT_DOUBLE_EQ(shipped->bias, (*file)->bias);
  EXPECT_DOUBLE_EQ(shipped->stage1_threshold, (*file)->stage1_threshold);
  EXPECT_DOUBLE_EQ(shipped->platt_a, (*file)->platt_a);
  EXPECT_DOUBLE_EQ(shipped->close_platt_a, (*file)->close_platt_a);
  EXPECT_EQ(shipped->nodes.size(), (*file)->nodes.size());
  EXPECT_EQ(shipped->cnn_onnx, (*file)->cnn_onnx);
  EXPECT_EQ(shipped->close_cnn_onnx, (*file)->close_cnn_onnx);
  EXPECT_EQ(shipped->close_cnn_patch_px, (*file)->close_cnn_patch_px);
  EXPECT_EQ(cv::norm(shipped->kernels[3], (*file)->kernels[3], cv::NORM_INF), 0.0);
}

// A forest as the trainer grows one (depth 14, sqrt(features) per split; fewer trees and samples),
// written and loaded: the shipped model's second stage is a CNN, so the flattening is checked on
// this one.
TEST(VictimDetectorModel, TheFlattenedForestVotesAsRTrees) {
  VictimDetectorModel trained;
  trained.SetLinear(std::vector<double>(kWindowFeatures, 0.01), -0.5);
  cv::Mat x(600, kForestFeatures, CV_32F), y(600, 1, CV_32S);
  cv::theRNG().state = 11;
  cv::randu(x, 0.0, 1.0);
  for (int i = 0; i < y.rows; ++i) y.at<int>(i) = x.at<float>(i, 0) + x.at<float>(i, 7) > 1.0f ? 1 : 0;
  trained.forest = cv::ml::RTrees::create();
  trained.forest->setMaxDepth(14);
  trained.forest->setMinSampleCount(2);
  trained.forest->setActiveVarCount(34);
  trained.forest->setTermCriteria(cv::TermCriteria(cv::TermCriteria::MAX_ITER, 12, 0));
  ASSERT_TRUE(trained.forest->train(cv::ml::TrainData::create(x, cv::ml::ROW_SAMPLE, y)));
  trained.training_seeds = {7000001};
  trained.calibration_seeds = {7100001};
  const std::string path = ::testing::TempDir() + "/flattened_forest.yml";
  ASSERT_TRUE(SaveDetectorModel(trained, path).ok());
  Result<std::shared_ptr<const VictimDetectorModel>> loaded = LoadDetectorModel(path);
  ASSERT_TRUE(loaded.ok()) << loaded.error().ToString();
  const std::shared_ptr<const VictimDetectorModel> m = *loaded;
  std::mt19937_64 rng(3);
  // Feature values around the split thresholds: random draws from the thresholds themselves.
  std::vector<float> thresholds;
  for (const VictimDetectorModel::ForestNode& n : m->nodes) {
    if (n.var >= 0) thresholds.push_back(n.threshold);
  }
  ASSERT_GT(thresholds.size(), 100u);
  cv::Mat probe(200, m->forest_inputs(), CV_32F);
  std::uniform_int_distribution<std::size_t> pick(0, thresholds.size() - 1);
  for (int i = 0; i < probe.rows; ++i) {
    for (int j = 0; j < probe.cols; ++j) probe.at<float>(i, j) = thresholds[pick(rng)];
  }
  cv::Mat votes;
  m->forest->getVotes(probe, votes, 0);
  const int person_col = votes.at<int>(0, 0) == 1 ? 0 : 1;
  for (int i = 0; i < probe.rows; ++i) {
    const double trees = votes.at<int>(i + 1, 0) + votes.at<int>(i + 1, 1);
    EXPECT_DOUBLE_EQ(m->Votes(probe.ptr<float>(i)), votes.at<int>(i + 1, person_col) / trees) << "sample " << i;
  }
}

TEST(VictimDetectorModel, ConfidenceIsACalibratedIncreasingProbability) {
  const std::shared_ptr<const VictimDetectorModel> m = ShippedDetectorModel();
  EXPECT_LT(m->platt_a, 0.0);  // more votes, more confidence
  double last = -1;
  // The second stage's score: the forest's vote fraction [0, 1], or the CNN's logit.
  const double lo = m->has_cnn() ? -10.0 : 0.0, hi = m->has_cnn() ? 10.0 : 1.0;
  for (double v = lo; v <= hi; v += (hi - lo) / 20) {
    const double p = m->Probability(v);
    EXPECT_GE(p, 0.0);
    EXPECT_LE(p, 1.0);
    EXPECT_GT(p, last);
    last = p;
  }
}

TEST(VictimDetectorModel, AModelOfAnotherLayoutIsRefusedWithTheReason) {
  const std::string path = ::testing::TempDir() + "/other_layout.yml";
  {
    cv::FileStorage fs(path, cv::FileStorage::WRITE);
    fs << "format_version" << 1 << "canonical_px_per_m" << 8.0 << "shrink" << 4;
  }
  Result<std::shared_ptr<const VictimDetectorModel>> m = LoadDetectorModel(path);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().message().find("retrain"), std::string::npos) << m.error().ToString();
  EXPECT_FALSE(LoadDetectorModel(path + ".missing").ok());
}

// A small model with a forest of `inputs` inputs (random data: the file format is under test).
VictimDetectorModel SmallModel(int inputs, int blob_features) {
  VictimDetectorModel m;
  m.SetLinear(std::vector<double>(kWindowFeatures, 0.01), -0.5);
  cv::Mat x(60, inputs, CV_32F), y(60, 1, CV_32S);
  cv::theRNG().state = 5;
  cv::randu(x, 0.0, 1.0);
  for (int i = 0; i < y.rows; ++i) y.at<int>(i) = i % 2;
  m.forest = cv::ml::RTrees::create();
  m.forest->setMaxDepth(3);
  m.forest->setTermCriteria(cv::TermCriteria(cv::TermCriteria::MAX_ITER, 3, 0));
  EXPECT_TRUE(m.forest->train(cv::ml::TrainData::create(x, cv::ml::ROW_SAMPLE, y)));
  m.blob_features = blob_features;
  m.training_seeds = {7000001};
  m.calibration_seeds = {7100001};
  m.recipe = "swarmbox-train-detector --training-sets 1 --trees 3";
  return m;
}

std::string ReadAll(const std::string& path) {
  std::ifstream f(path);
  std::stringstream text;
  text << f.rdbuf();
  return text.str();
}

TEST(VictimDetectorModel, AModelWithBlobFeaturesKeepsThemAndItsRecipeThroughTheFile) {
  const std::string path = ::testing::TempDir() + "/blob_model.yml";
  ASSERT_TRUE(SaveDetectorModel(SmallModel(kForestFeatures + kBlobFeatures, kBlobFeatures), path).ok());
  Result<std::shared_ptr<const VictimDetectorModel>> m = LoadDetectorModel(path);
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  EXPECT_EQ((*m)->blob_features, kBlobFeatures);
  EXPECT_EQ((*m)->forest_inputs(), kForestFeatures + kBlobFeatures);
  EXPECT_EQ((*m)->recipe, "swarmbox-train-detector --training-sets 1 --trees 3");
}

// A window-only model is written in format 1's layout (as the shipped model is: the default
// training step reproduces it) and loads and runs without blob features.
TEST(VictimDetectorModel, AFormatOneModelStillLoadsAndRunsWithoutBlobFeatures) {
  const std::string path = ::testing::TempDir() + "/format1_model.yml";
  ASSERT_TRUE(SaveDetectorModel(SmallModel(kForestFeatures, 0), path).ok());
  const std::string text = ReadAll(path);
  EXPECT_NE(text.find("format_version: 1"), std::string::npos);
  EXPECT_EQ(text.find("blob_features"), std::string::npos);
  EXPECT_EQ(text.find("recipe"), std::string::npos);
  Result<std::shared_ptr<const VictimDetectorModel>> m = LoadDetectorModel(path);
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  EXPECT_EQ((*m)->blob_features, 0);
  VictimDetector det(*m, VictimDetectorParams{});
  cv::Mat img(120, 160, CV_8UC3, cv::Scalar(60, 110, 80));
  std::vector<ImageBlob> blobs;
  det.Detect(img, 15.0, &blobs);  // runs on the window features alone
  for (const ImageBlob& b : blobs) EXPECT_GE(b.confidence, 0.0);
}

TEST(VictimDetectorModel, AForestThatDoesNotTakeTheBlobFeaturesItClaimsIsRefused) {
  const std::string path = ::testing::TempDir() + "/wrong_inputs.yml";
  ASSERT_TRUE(SaveDetectorModel(SmallModel(kForestFeatures, kBlobFeatures), path).ok());
  Result<std::shared_ptr<const VictimDetectorModel>> m = LoadDetectorModel(path);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().message().find("wrong inputs"), std::string::npos) << m.error().ToString();
}

}  // namespace
}  // namespace swarmbox::swarm
