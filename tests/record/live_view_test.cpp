// The page of the live view in headless Chromium (tests/js/page_check.mjs on puppeteer-core): it
// loads from a LiveServer holding a SAR trial's channels (live_scenario.hpp), draws the drones
// where the trial had them, and the time slider moves them.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>

#include "live_scenario.hpp"
#include "support/child_process.hpp"
#include "support/files.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/record/live_server.hpp"

namespace swarmbox::record {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using swarmbox::testing::ReadWholeFile;

const std::string kJsDir = SWARMBOX_TESTS_JS_DIR;
const std::string kNode = SWARMBOX_NODE_EXE;
const std::string kChromium = SWARMBOX_CHROMIUM_EXE;

::testing::AssertionResult BrowserReady() {
  if (kNode.empty() || !fs::exists(kNode)) {
    return ::testing::AssertionFailure() << "node was not found at configure time: run `sudo bash "
                                            "scripts/setup.sh` (installs nodejs), then reconfigure";
  }
  if (!fs::exists(kJsDir + "/node_modules/puppeteer-core")) {
    return ::testing::AssertionFailure() << "the JS test packages are missing: run `(cd " << kJsDir
                                         << " && npm ci)` (scripts/setup.sh does)";
  }
  if (kChromium.empty() || !fs::exists(kChromium)) {
    return ::testing::AssertionFailure() << "chromium was not found at configure time: run `sudo apt-get "
                                            "install chromium` (scripts/setup.sh does), then reconfigure";
  }
  return ::testing::AssertionSuccess();
}

// Runs page_check.mjs against `url`; its JSON report (the test fails on exit != 0 with it).
yaml::Node CheckPage(const std::string& url, const std::string& dir, const std::string& screenshot) {
  auto run = swarmbox::testing::RunToEnd(
      {kNode, kJsDir + "/page_check.mjs", url, "--drones",
       std::to_string(swarmbox::testing::kScenarioDrones.size()), "--chromium", kChromium, "--screenshot",
       screenshot, "--timeout-ms", "90000"},
      120s, dir);
  EXPECT_TRUE(run) << run.error().ToString();
  if (!run) return {};
  EXPECT_EQ(run->code, 0) << run->out << "\n" << run->err;
  auto doc = yaml::Parse(run->out, "page_check");
  EXPECT_TRUE(doc) << run->out << "\n" << run->err;
  return doc ? *doc : yaml::Node{};
}

// Where the page drew each drone at its time t is where the trial had it.
void ExpectTruePositions(const yaml::Node& state) {
  const double t = *state.Find("t")->AsDouble();
  const yaml::Node* drones = state.Find("drones");
  ASSERT_NE(drones, nullptr);
  ASSERT_EQ(drones->entries().size(), swarmbox::testing::kScenarioDrones.size());
  for (const auto& [name, d] : drones->entries()) {
    const auto truth = swarmbox::testing::ScenarioPosition(name.scalar(), t);
    const auto& pos = d.Find("pos")->items();
    EXPECT_NEAR(*pos[0].AsDouble(), truth[0], 0.6) << name.scalar() << " at t=" << t;
    EXPECT_NEAR(*pos[1].AsDouble(), truth[1], 0.6) << name.scalar() << " at t=" << t;
  }
}

class LiveViewTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = swarmbox::testing::MakeTempDir("live_view_test_");
    ASSERT_FALSE(dir_.empty());
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
};

TEST_F(LiveViewTest, ThePageDrawsTheDronesWhereTheTrialHadThemAndTheSliderMovesThem) {
  ASSERT_TRUE(BrowserReady());
  // Given a live server that has had a whole trial written to it (the page follows the head)...
  auto server = LiveServer::Start({.port = 0, .name = "swarmbox live test"});
  ASSERT_TRUE(server) << server.error().ToString();
  ASSERT_TRUE(swarmbox::testing::WriteSarScenario(**server));
  // When Chromium loads the page, waits for the drones and moves the slider...
  const yaml::Node report = CheckPage((*server)->url(), dir_, dir_ + "/live.png");
  ASSERT_TRUE(report.is_mapping());
  // Then it followed the head, drew the four drones where they were at each time it showed...
  const yaml::Node* before = report.Find("before");
  ASSERT_NE(before, nullptr);
  EXPECT_EQ(*before->Find("mode")->AsString(), "live");
  EXPECT_NEAR(*before->Find("t")->AsDouble(), swarmbox::testing::kScenarioDurationS, 0.01);
  ExpectTruePositions(*before);
  ExpectTruePositions(*report.Find("quarter"));
  ExpectTruePositions(*report.Find("after"));
  // ... the slider moved them, the leader of term 2 is marked, the newest camera frame of the
  // selected drone shows at the end (a late page gets no older ones), and the events jump to
  // their times.
  EXPECT_GE(*report.Find("moved")->AsInt(), 3);
  EXPECT_EQ(*report.Find("after")->Find("leader")->AsString(), "scout_2");
  EXPECT_EQ(*report.Find("cameraShown")->AsBool(), false);
  EXPECT_EQ(*report.Find("cameraAtEnd")->AsBool(), true);
  EXPECT_GE(*before->Find("events")->AsInt(), 8);
  EXPECT_TRUE(fs::file_size(dir_ + "/live.png") > 10000u);
}

}  // namespace
}  // namespace swarmbox::record
