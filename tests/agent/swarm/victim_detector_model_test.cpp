// The shipped detector model (agent/swarm/models/, written by `cmake --build build --target
// train-detector`): it loads, it was trained and calibrated on scene seeds the evaluation never
// uses, the binary carries the same model as the committed file, and the flattened forest the
// detector runs decides as OpenCV's RTrees.
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
  EXPECT_EQ(shipped->nodes.size(), (*file)->nodes.size());
  EXPECT_EQ(cv::norm(shipped->kernels[3], (*file)->kernels[3], cv::NORM_INF), 0.0);
}

TEST(VictimDetectorModel, TheFlattenedForestVotesAsRTrees) {
  const std::shared_ptr<const VictimDetectorModel> m = ShippedDetectorModel();
  std::mt19937_64 rng(3);
  // Feature values around the split thresholds: random draws from the thresholds themselves.
  std::vector<float> thresholds;
  for (const VictimDetectorModel::ForestNode& n : m->nodes) {
    if (n.var >= 0) thresholds.push_back(n.threshold);
  }
  ASSERT_FALSE(thresholds.empty());
  cv::Mat x(200, m->forest_inputs(), CV_32F);
  std::uniform_int_distribution<std::size_t> pick(0, thresholds.size() - 1);
  for (int i = 0; i < x.rows; ++i) {
    for (int j = 0; j < x.cols; ++j) x.at<float>(i, j) = thresholds[pick(rng)];
  }
  cv::Mat votes;
  m->forest->getVotes(x, votes, 0);
  const int person_col = votes.at<int>(0, 0) == 1 ? 0 : 1;
  for (int i = 0; i < x.rows; ++i) {
    const double trees = votes.at<int>(i + 1, 0) + votes.at<int>(i + 1, 1);
    EXPECT_DOUBLE_EQ(m->Votes(x.ptr<float>(i)), votes.at<int>(i + 1, person_col) / trees) << "sample " << i;
  }
}

TEST(VictimDetectorModel, ConfidenceIsACalibratedIncreasingProbability) {
  const std::shared_ptr<const VictimDetectorModel> m = ShippedDetectorModel();
  EXPECT_LT(m->platt_a, 0.0);  // more votes, more confidence
  double last = -1;
  for (double v = 0; v <= 1.0; v += 0.05) {
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
