// The page of the live view in headless Chromium (tests/js/page_check.mjs on puppeteer-core): it
// loads from a LiveServer holding a SAR trial's channels (live_scenario.hpp), live or replayed by
// `swarmbox view` from a recording.mcap, draws the drones where the trial had them, and the time
// slider moves them. The replay's screenshot is left in the build folder as view.png (the README's
// docs/view.png is a copy).
#include <gtest/gtest.h>

#include <csignal>
#include <fstream>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>

#include "live_scenario.hpp"
#include "support/child_process.hpp"
#include "support/files.hpp"
#include "support/wait_until.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/record/live_server.hpp"
#include "swarmbox/record/mcap.hpp"

namespace swarmbox::record {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using swarmbox::testing::ReadWholeFile;

const std::string kJsDir = SWARMBOX_TESTS_JS_DIR;
const std::string kNode = SWARMBOX_NODE_EXE;
const std::string kChromium = SWARMBOX_CHROMIUM_EXE;
const std::string kSwarmbox = SWARMBOX_CLI_EXE;

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

// A trial folder with the scenario as its recording.mcap.
void WriteRecording(const std::string& run_dir) {
  fs::create_directories(run_dir);
  auto writer = McapWriter::Create(run_dir + "/recording.mcap");
  ASSERT_TRUE(writer) << writer.error().ToString();
  ASSERT_TRUE(swarmbox::testing::WriteSarScenario(**writer));
  ASSERT_TRUE((*writer)->Close());
}

TEST_F(LiveViewTest, SwarmboxViewReplaysARecordingInThePageUntilCtrlC) {
  ASSERT_TRUE(BrowserReady());
  const std::string run_dir = dir_ + "/sar-search-20261126T120000Z";
  WriteRecording(run_dir);
  // Given `swarmbox view` on a trial folder, on any free port...
  const std::string out = dir_ + "/view.out", err = dir_ + "/view.err";
  auto view = swarmbox::testing::ChildProcess::Spawn({kSwarmbox, "view", run_dir, "--addr", "127.0.0.1:0"}, out, err);
  ASSERT_TRUE(view) << view.error().ToString();
  std::string url;
  ASSERT_TRUE(swarmbox::testing::WaitUntil(
      [&] {
        const std::string text = ReadWholeFile(out);
        const auto at = text.find("view: http://");
        if (at == std::string::npos || text.find('\n', at) == std::string::npos) return !view->running();
        url = text.substr(at + 6, text.find('\n', at) - at - 6);
        return true;
      },
      60s));
  ASSERT_FALSE(url.empty()) << ReadWholeFile(out) << ReadWholeFile(err);
  EXPECT_EQ(url.rfind("http://127.0.0.1:", 0), 0u) << url;
  // When Chromium loads the page and moves the slider...
  const yaml::Node report = CheckPage(url, dir_, "view.png");
  ASSERT_TRUE(report.is_mapping());
  // Then the replay starts at the first message, draws the drones where they were, the slider
  // moves them, the camera of the selected drone shows at every time, and events jump.
  const yaml::Node* before = report.Find("before");
  EXPECT_EQ(*before->Find("mode")->AsString(), "replay");
  EXPECT_NEAR(*before->Find("t")->AsDouble(), 0.0, 0.01);
  EXPECT_NEAR(*before->Find("t1")->AsDouble(), swarmbox::testing::kScenarioDurationS, 0.01);
  ExpectTruePositions(*before);
  ExpectTruePositions(*report.Find("quarter"));
  ExpectTruePositions(*report.Find("after"));
  EXPECT_GE(*report.Find("moved")->AsInt(), 3);
  EXPECT_EQ(*report.Find("cameraShown")->AsBool(), true);
  EXPECT_EQ(*report.Find("after")->Find("leader")->AsString(), "scout_2");
  EXPECT_EQ(*report.Find("after")->Find("links")->AsInt(), 6) << "each pair of the 4 drones, from each one's report";
  EXPECT_TRUE(report.Find("eventJump")->is_mapping());
  EXPECT_GT(fs::file_size("view.png"), 10000u);
  // ... and Ctrl-C ends it cleanly.
  ASSERT_TRUE(view->Signal(SIGINT));
  const std::optional<int> code = view->Wait(10s);
  ASSERT_TRUE(code.has_value());
  EXPECT_EQ(*code, 0) << ReadWholeFile(err);
}

TEST_F(LiveViewTest, SwarmboxViewWithoutARecordingSaysSoAndExits2) {
  auto run = swarmbox::testing::RunToEnd({kSwarmbox, "view", dir_, "--addr", "127.0.0.1:0"}, 30s, dir_);
  ASSERT_TRUE(run) << run.error().ToString();
  EXPECT_EQ(run->code, 2);
  EXPECT_NE(run->err.find(dir_ + "/recording.mcap: no recording there"), std::string::npos) << run->err;
  EXPECT_EQ(run->out, "");

  std::ofstream(dir_ + "/recording.mcap") << "not an mcap file";
  run = swarmbox::testing::RunToEnd({kSwarmbox, "view", dir_}, 30s, dir_);
  ASSERT_TRUE(run) << run.error().ToString();
  EXPECT_EQ(run->code, 2) << run->err;
  EXPECT_NE(run->err.find("recording.mcap"), std::string::npos) << run->err;

  run = swarmbox::testing::RunToEnd({kSwarmbox, "view", dir_, "--addr", "localhost"}, 30s, dir_);
  ASSERT_TRUE(run) << run.error().ToString();
  EXPECT_EQ(run->code, 2);
  EXPECT_NE(run->err.find("expected ADDR:PORT"), std::string::npos) << run->err;
}

}  // namespace
}  // namespace swarmbox::record
