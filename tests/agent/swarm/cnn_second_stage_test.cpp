// The detector's convolutional second stage (victim_detector_model.hpp format 3): the candidate
// patches (candidate_patch.hpp) are sampled at a fixed metric scale and are the same pixels
// through the trainer's path (CandidatePatch, CandidatePatchSampler) and the detector's
// (VictimDetector::CnnPatch); cv::dnn gives torch's logits for the fixture network; a model that
// carries a CNN saves, loads and scores every candidate with it, batched as one patch at a time.
//
// The fixture data/patch_cnn_fixture.onnx (an untrained network of train_cnn.py's architecture with
// seeded weights) and its .logits.txt (torch's logits for FixturePatches(4)) were written by
//   /usr/bin/python3 tools/train_detector/train_cnn.py --test-fixture --seed 1
//       --out tests/agent/swarm/data/patch_cnn_fixture.onnx   (one command line)
// (no Python at test time).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "swarmbox/swarm/candidate_patch.hpp"
#include "swarmbox/swarm/victim_detector.hpp"
#include "swarmbox/swarm/victim_detector_model.hpp"

#ifndef SWARMBOX_SWARM_TEST_DATA_DIR
#error "SWARMBOX_SWARM_TEST_DATA_DIR must point at tests/agent/swarm/data"
#endif

namespace swarmbox::swarm {
namespace {

const std::string kFixture = std::string(SWARMBOX_SWARM_TEST_DATA_DIR) + "/patch_cnn_fixture.onnx";
constexpr double kLogitTolerance = 1e-4;

std::vector<std::uint8_t> ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::vector<std::uint8_t> bytes(in ? static_cast<std::size_t>(in.tellg()) : 0);
  in.seekg(0);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return bytes;
}

// train_cnn.py fixture_patches(): pixel (n, i, j, c) = (31 n + 7 i + 13 j + 29 c + i j) mod 256.
std::vector<cv::Mat> FixturePatches(int count) {
  std::vector<cv::Mat> patches;
  for (int n = 0; n < count; ++n) {
    cv::Mat p(kCnnPatchPx, kCnnPatchPx, CV_8UC3);
    for (int i = 0; i < kCnnPatchPx; ++i) {
      for (int j = 0; j < kCnnPatchPx; ++j) {
        for (int c = 0; c < 3; ++c) p.at<cv::Vec3b>(i, j)[c] = static_cast<std::uint8_t>((31 * n + 7 * i + 13 * j + 29 * c + i * j) % 256);
      }
    }
    patches.push_back(p);
  }
  return patches;
}

// The network's logits for `patches`, one forward, with the detector's input normalisation.
std::vector<float> Logits(cv::dnn::Net& net, const std::vector<cv::Mat>& patches) {
  cv::Mat blob = cv::dnn::blobFromImages(patches, kCnnInputScale, cv::Size(kCnnPatchPx, kCnnPatchPx),
                                         cv::Scalar::all(kCnnInputMean), false, false, CV_32F);
  net.setInput(blob);
  cv::Mat out = net.forward();
  return std::vector<float>(out.ptr<float>(), out.ptr<float>() + out.total());
}

// The shipped first stage with the fixture network as its second stage (its 32 px patches,
// whatever the shipped model's); no cnn_onnx when the fixture file is missing.
VictimDetectorModel FixtureModel() {
  VictimDetectorModel m = *ShippedDetectorModel();
  m.cnn_onnx = ReadBytes(kFixture);
  m.cnn_patch_px = kCnnPatchPx;
  m.forest.release();
  m.nodes.clear();
  m.roots.clear();
  return m;
}

// `m` written to a file in the test's temporary folder and read back (the file removed): what a
// model file keeps of it, or why it cannot be read.
Result<std::shared_ptr<const VictimDetectorModel>> ThroughTheFile(const VictimDetectorModel& m) {
  const std::string path = ::testing::TempDir() + "/cnn_second_stage_model.yml.gz";
  if (Status st = SaveDetectorModel(m, path); !st) return st.error();
  Result<std::shared_ptr<const VictimDetectorModel>> loaded = LoadDetectorModel(path);
  std::remove(path.c_str());
  return loaded;
}

// Every candidate kept: no threshold, suppression or partial-view cap.
VictimDetectorParams EveryCandidate() {
  VictimDetectorParams all;
  all.min_confidence = 0.0;
  all.nms_radius_m = 0.0;
  all.partial_confidence_cap = 1.0;
  return all;
}

// A seeded 320 x 240 frame: textured ground and a few coloured rectangles and discs.
cv::Mat TestFrame() {
  std::mt19937 rng(19);
  cv::Mat frame(240, 320, CV_8UC3, cv::Scalar(70, 110, 95));
  cv::Mat noise(frame.size(), CV_8UC3);
  cv::randn(noise, cv::Scalar::all(0), cv::Scalar::all(12));
  frame += noise;
  std::uniform_int_distribution<int> x(20, 300), y(20, 220), colour(0, 255);
  for (int k = 0; k < 8; ++k) {
    const cv::Scalar c(colour(rng), colour(rng), colour(rng));
    if (k % 2 == 0) {
      cv::rectangle(frame, cv::Rect(x(rng), y(rng), 12 + k * 3, 8), c, cv::FILLED);
    } else {
      cv::circle(frame, cv::Point(x(rng), y(rng)), 4 + k, c, cv::FILLED);
    }
  }
  return frame;
}

TEST(CandidatePatch, SamplesAThreeMetreSquareAtTheFixedScaleAroundTheCentre) {
  // The search model's 32 px (10.7 px/m) and the close-look model's 48 px (16 px/m).
  for (const int px : {kCnnPatchPx, 48}) {
    // Given a 1 x 1 m red square on grey ground, centred on pixel (99.5, 79.5), at 20 px/m.
    constexpr double kPxPerM = 20.0;
    cv::Mat frame(200, 200, CV_8UC3, cv::Scalar(100, 100, 100));
    cv::rectangle(frame, cv::Rect(90, 70, 20, 20), cv::Scalar(0, 0, 255), cv::FILLED);
    // When its patch is taken at the square's centre.
    CandidatePatchSampler sampler(px);
    sampler.SetFrame(frame, kPxPerM);
    cv::Mat patch;
    sampler.Extract({99.5, 79.5}, &patch);
    // Then the patch is px square, red within 0.5 m of its centre and grey beyond.
    ASSERT_EQ(patch.rows, px);
    ASSERT_EQ(patch.cols, px);
    ASSERT_EQ(patch.type(), CV_8UC3);
    const double px_per_m = px / kCnnPatchM;
    const int mid = px / 2;
    const int inside = static_cast<int>(0.35 * px_per_m), outside = static_cast<int>(0.7 * px_per_m);
    constexpr double kLevels = 2;  // rounding of the area average and the bilinear taps
    auto off = [&](int r, int c, cv::Vec3b want) {
      return cv::norm(cv::Vec3d(patch.at<cv::Vec3b>(r, c)) - cv::Vec3d(want), cv::NORM_INF);
    };
    for (int d : {-inside - 1, inside}) {
      EXPECT_LE(off(mid + d, mid + d, {0, 0, 255}), kLevels) << px << " " << d;
    }
    for (int d : {-outside - 1, outside}) {
      EXPECT_LE(off(mid + d, mid, {100, 100, 100}), kLevels) << px << " " << d;
      EXPECT_LE(off(mid, mid + d, {100, 100, 100}), kLevels) << px << " " << d;
    }
  }
  EXPECT_FALSE(ValidCnnPatchPx(36));
  EXPECT_FALSE(ValidCnnPatchPx(8));
}

TEST(CandidatePatch, IsDeterministicAndTheDetectorSeesTheTrainersPixels) {
  const cv::Mat frame = TestFrame();
  // The 32 px patches of CandidatePatch() and 48 px ones (the trainer's --cnn-patch-px 48).
  for (const int px : {kCnnPatchPx, 48}) {
    auto model = std::make_shared<VictimDetectorModel>(*ShippedDetectorModel());
    model->cnn_patch_px = px;
    for (double px_per_m : {6.0, 15.5, 40.0}) {  // coarser than the patch, the 30 m scale, finer (shrunk)
      VictimDetector det(model, {});
      const auto& cands = det.Candidates(frame, px_per_m, 24, -1e30);
      ASSERT_FALSE(cands.empty()) << px_per_m;
      for (const VictimDetector::Candidate& c : cands) {
        cv::Mat from_detector, from_trainer, again;
        det.CnnPatch(c, &from_detector);
        CandidatePatchSampler sampler(px);  // as the trainer exports them, a fresh frame each
        sampler.SetFrame(frame, px_per_m);
        sampler.Extract(det.CentrePx(c), &from_trainer);
        if (px == kCnnPatchPx) {
          CandidatePatch(frame, px_per_m, det.CentrePx(c), &again);
        } else {
          sampler.Extract(det.CentrePx(c), &again);
        }
        ASSERT_EQ(from_detector.rows, px);
        EXPECT_EQ(cv::norm(from_detector, from_trainer, cv::NORM_INF), 0.0) << px << " " << px_per_m;
        EXPECT_EQ(cv::norm(from_trainer, again, cv::NORM_INF), 0.0) << px << " " << px_per_m;
      }
    }
  }
}

TEST(VictimDetectorCandidates, AreTheBestScoreWithinTheSpacingAndTheSpacingThinsThem) {
  // Given one frame's candidates (every local maximum, any score) at one cell and at 1 m spacing.
  const cv::Mat frame = TestFrame();
  constexpr double kPxPerM = 15.5;
  VictimDetectorParams fine, wide;
  fine.candidate_spacing_m = 0.25;
  wide.candidate_spacing_m = 1.0;
  VictimDetector det_fine(ShippedDetectorModel(), fine), det_wide(ShippedDetectorModel(), wide);
  const std::vector<VictimDetector::Candidate> all = det_fine.Candidates(frame, kPxPerM, 100000, -1e30);
  const std::vector<VictimDetector::Candidate> thinned = det_wide.Candidates(frame, kPxPerM, 100000, -1e30);
  // Then the wider spacing keeps fewer, each of them one of the fine ones, and no fine candidate
  // within 1 m (4 cells either way) of a kept one scores higher than it.
  ASSERT_FALSE(thinned.empty());
  EXPECT_LT(thinned.size(), all.size());
  for (const VictimDetector::Candidate& k : thinned) {
    bool found = false;
    for (const VictimDetector::Candidate& c : all) {
      found = found || (c.row == k.row && c.col == k.col);
      if (std::abs(c.row - k.row) <= 4 && std::abs(c.col - k.col) <= 4) {
        EXPECT_LE(c.score, k.score);
      }
    }
    EXPECT_TRUE(found) << k.row << "," << k.col;
  }
  // And two kept candidates are more than 4 cells apart unless they tie.
  for (std::size_t i = 0; i < thinned.size(); ++i) {
    for (std::size_t j = i + 1; j < thinned.size(); ++j) {
      const bool near =
          std::abs(thinned[i].row - thinned[j].row) <= 4 && std::abs(thinned[i].col - thinned[j].col) <= 4;
      if (near) {
        EXPECT_EQ(thinned[i].score, thinned[j].score);
      }
    }
  }
}

TEST(CnnSecondStage, CvDnnGivesTorchsLogitsForTheFixtureNetwork) {
  const std::vector<std::uint8_t> onnx = ReadBytes(kFixture);
  ASSERT_FALSE(onnx.empty()) << kFixture;
  cv::dnn::Net net = cv::dnn::readNetFromONNX(reinterpret_cast<const char*>(onnx.data()), onnx.size());
  ASSERT_FALSE(net.empty());
  std::ifstream expected_file(kFixture + ".logits.txt");
  std::vector<float> expected(4);
  for (float& v : expected) ASSERT_TRUE(expected_file >> v);
  const std::vector<float> logits = Logits(net, FixturePatches(4));
  ASSERT_EQ(logits.size(), expected.size());
  for (std::size_t i = 0; i < logits.size(); ++i) EXPECT_NEAR(logits[i], expected[i], kLogitTolerance) << i;
}

TEST(CnnSecondStage, AModelWithACnnRoundTripsAndScoresEachCandidateByItsPatch) {
  // Given the shipped first stage with the fixture network as its second stage, saved and loaded.
  VictimDetectorModel with_cnn = FixtureModel();
  ASSERT_FALSE(with_cnn.cnn_onnx.empty()) << kFixture;
  Result<std::shared_ptr<const VictimDetectorModel>> loaded = ThroughTheFile(with_cnn);
  ASSERT_TRUE(loaded.ok()) << loaded.error().ToString();
  ASSERT_TRUE((*loaded)->has_cnn());
  EXPECT_EQ((*loaded)->cnn_onnx, with_cnn.cnn_onnx);
  EXPECT_TRUE((*loaded)->forest.empty());
  EXPECT_EQ((*loaded)->stage1_threshold, with_cnn.stage1_threshold);
  // When the detector runs it on a frame (every candidate kept).
  const VictimDetectorParams all = EveryCandidate();
  VictimDetector det(*loaded, all);
  const cv::Mat frame = TestFrame();
  constexpr double kPxPerM = 15.5;
  std::vector<ImageBlob> blobs;
  det.Detect(frame, kPxPerM, &blobs);
  ASSERT_FALSE(blobs.empty());
  // Then each detection's score is the network's logit for its own patch alone, and its
  // confidence the sigmoid of that.
  cv::dnn::Net net = cv::dnn::readNetFromONNX(reinterpret_cast<const char*>(with_cnn.cnn_onnx.data()),
                                              with_cnn.cnn_onnx.size());
  for (const ImageBlob& b : blobs) {
    cv::Mat patch;
    CandidatePatch(frame, kPxPerM, b.centroid_px, &patch);
    const std::vector<float> alone = Logits(net, {patch});
    ASSERT_EQ(alone.size(), 1u);
    EXPECT_NEAR(b.votes, alone[0], kLogitTolerance);
    EXPECT_NEAR(b.confidence, with_cnn.Probability(b.votes), 1e-12);
  }
  EXPECT_EQ((*loaded)->cnn_symmetries, 1);  // a file without the field: the network once
}

// The patch turned by 90 degrees `turns` times (counter-clockwise), by transposes and flips.
cv::Mat Turned(const cv::Mat& patch, int turns) {
  cv::Mat out = patch.clone();
  for (int k = 0; k < turns; ++k) {
    cv::Mat t;
    cv::transpose(out, t);
    cv::flip(t, out, 0);
  }
  return out;
}

TEST(CnnSecondStage, WithSymmetriesAScoreIsTheMeanLogitOverThePatchsTurnsAndMirrorImages) {
  VictimDetectorModel with_cnn = FixtureModel();
  ASSERT_FALSE(with_cnn.cnn_onnx.empty()) << kFixture;
  cv::dnn::Net net = cv::dnn::readNetFromONNX(reinterpret_cast<const char*>(with_cnn.cnn_onnx.data()),
                                              with_cnn.cnn_onnx.size());
  const VictimDetectorParams all = EveryCandidate();
  const cv::Mat frame = TestFrame();
  constexpr double kPxPerM = 15.5;
  for (const int symmetries : {4, 8}) {
    // Given the fixture network scoring each patch in `symmetries` of the square's symmetries,
    // saved and loaded.
    with_cnn.cnn_symmetries = symmetries;
    Result<std::shared_ptr<const VictimDetectorModel>> loaded = ThroughTheFile(with_cnn);
    ASSERT_TRUE(loaded.ok()) << loaded.error().ToString();
    EXPECT_EQ((*loaded)->cnn_symmetries, symmetries);
    // When the detector runs it on a frame.
    VictimDetector det(*loaded, all);
    std::vector<ImageBlob> blobs;
    det.Detect(frame, kPxPerM, &blobs);
    ASSERT_FALSE(blobs.empty());
    // Then each score is the mean of the network's logits for its patch's four turns (and with 8,
    // their mirror images too), which differs from the patch's own logit.
    int differ = 0;
    for (const ImageBlob& b : blobs) {
      cv::Mat patch;
      CandidatePatch(frame, kPxPerM, b.centroid_px, &patch);
      std::vector<cv::Mat> views;
      for (int turns = 0; turns < 4; ++turns) {
        views.push_back(Turned(patch, turns));
        if (symmetries == 8) {
          cv::Mat mirrored;
          cv::flip(views.back(), mirrored, 1);
          views.push_back(mirrored);
        }
      }
      const std::vector<float> logits = Logits(net, views);
      double mean = 0;
      for (float v : logits) mean += v / static_cast<double>(logits.size());
      EXPECT_NEAR(b.votes, mean, kLogitTolerance) << symmetries;
      differ += std::abs(b.votes - logits[0]) > 10 * kLogitTolerance ? 1 : 0;
    }
    EXPECT_GT(differ, 0) << symmetries;
  }
  // And a count the detector does not know is refused when the file is loaded.
  with_cnn.cnn_symmetries = 3;
  EXPECT_FALSE(ThroughTheFile(with_cnn).ok());
}

TEST(CnnSecondStage, ACloseSigmoidGivesTheConfidenceOnFramesAtLeastThatFine) {
  // Given the fixture network with a second sigmoid for frames of >= 20 px/m, saved and loaded.
  VictimDetectorModel with_cnn = FixtureModel();
  ASSERT_FALSE(with_cnn.cnn_onnx.empty()) << kFixture;
  with_cnn.close_px_per_m = 0;  // none: one sigmoid for every frame
  EXPECT_DOUBLE_EQ(with_cnn.Probability(0.7, 100.0), with_cnn.Probability(0.7));
  with_cnn.close_px_per_m = 20.0;
  with_cnn.close_platt_a = -2.0;
  with_cnn.close_platt_b = 0.5;
  Result<std::shared_ptr<const VictimDetectorModel>> loaded = ThroughTheFile(with_cnn);
  ASSERT_TRUE(loaded.ok()) << loaded.error().ToString();
  EXPECT_EQ((*loaded)->close_px_per_m, 20.0);
  EXPECT_EQ((*loaded)->close_platt_a, -2.0);
  EXPECT_EQ((*loaded)->close_platt_b, 0.5);
  const VictimDetectorParams all = EveryCandidate();
  VictimDetector det(*loaded, all);
  const cv::Mat frame = TestFrame();
  // When it runs on the frame at the search altitude's 15.5 px/m and at 25 px/m (a close look).
  for (const double px_per_m : {15.5, 25.0}) {
    std::vector<ImageBlob> blobs;
    det.Detect(frame, px_per_m, &blobs);
    ASSERT_FALSE(blobs.empty()) << px_per_m;
    // Then the first sigmoid gives the confidences of the coarser frame, the close one those of
    // the finer.
    for (const ImageBlob& b : blobs) {
      const double first = 1.0 / (1.0 + std::exp(with_cnn.platt_a * b.votes + with_cnn.platt_b));
      const double close = 1.0 / (1.0 + std::exp(-2.0 * b.votes + 0.5));
      EXPECT_NEAR(b.confidence, px_per_m < 20.0 ? first : close, 1e-12) << px_per_m;
      EXPECT_GT(std::abs(first - close), 1e-6);
    }
  }
}

TEST(CnnSecondStage, ACloseLookCnnScoresTheFramesAtLeastThatFineOnTheSameCandidates) {
  // Given the shipped model (its 48 px CNN) with the fixture network (32 px) as its close-look CNN
  // from 20 px/m, saved and loaded.
  VictimDetectorModel m = *ShippedDetectorModel();
  m.close_cnn_onnx = ReadBytes(kFixture);
  ASSERT_FALSE(m.close_cnn_onnx.empty()) << kFixture;
  ASSERT_NE(m.cnn_patch_px, kCnnPatchPx);
  m.close_cnn_patch_px = kCnnPatchPx;
  m.close_px_per_m = 20.0;
  m.close_platt_a = -2.0;
  m.close_platt_b = 0.5;
  Result<std::shared_ptr<const VictimDetectorModel>> loaded = ThroughTheFile(m);
  ASSERT_TRUE(loaded.ok()) << loaded.error().ToString();
  EXPECT_EQ((*loaded)->close_cnn_onnx, m.close_cnn_onnx);
  EXPECT_EQ((*loaded)->close_cnn_patch_px, kCnnPatchPx);
  // Its close view: the same first stage, the close CNN, its patches and the close sigmoid alone.
  const VictimDetectorModel view = (*loaded)->CloseView();
  EXPECT_EQ(view.cnn_onnx, m.close_cnn_onnx);
  EXPECT_EQ(view.cnn_patch_px, kCnnPatchPx);
  EXPECT_EQ(view.platt_a, -2.0);
  EXPECT_EQ(view.close_px_per_m, 0.0);
  EXPECT_FALSE(view.has_close_cnn());
  EXPECT_EQ(view.stage1_threshold, m.stage1_threshold);
  // When the detector runs on the frame as a search view (15.5 px/m) and a close look (25 px/m).
  const VictimDetectorParams all = EveryCandidate();
  VictimDetector det(*loaded, all), close(std::make_shared<VictimDetectorModel>(view), all);
  VictimDetectorModel no_close_cnn = **loaded;
  no_close_cnn.close_cnn_onnx.clear();
  VictimDetector search(std::make_shared<VictimDetectorModel>(no_close_cnn), all);
  ASSERT_NE(det.close(), nullptr);
  EXPECT_EQ(search.close(), nullptr);
  const cv::Mat frame = TestFrame();
  for (const double px_per_m : {15.5, 25.0}) {
    std::vector<ImageBlob> got, want, other;
    det.Detect(frame, px_per_m, &got);
    (px_per_m < 20.0 ? search : close).Detect(frame, px_per_m, &want);
    search.Detect(frame, px_per_m, &other);
    // Then the coarser frame is scored as without a close CNN, the finer by the close view: the
    // same candidates, the fixture's logits through the close sigmoid, not the search CNN's.
    ASSERT_FALSE(got.empty()) << px_per_m;
    ASSERT_EQ(got.size(), want.size()) << px_per_m;
    int other_score = 0;
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].centroid_px, want[i].centroid_px) << px_per_m;
      EXPECT_DOUBLE_EQ(got[i].votes, want[i].votes) << px_per_m;
      EXPECT_DOUBLE_EQ(got[i].confidence, want[i].confidence) << px_per_m;
      other_score += i < other.size() && other[i].votes != got[i].votes ? 1 : 0;
    }
    EXPECT_EQ(other_score > 0, px_per_m >= 20.0) << px_per_m;
  }
  // A close CNN without the scale it takes over from is refused with the reason.
  m.close_px_per_m = 0;
  loaded = ThroughTheFile(m);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.error().ToString().find("close_px_per_m"), std::string::npos) << loaded.error().ToString();
}

}  // namespace
}  // namespace swarmbox::swarm
