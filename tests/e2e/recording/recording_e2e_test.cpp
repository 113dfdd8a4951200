// Every trial is recorded (issue #20.1, "Verified by an independent reader"): `swarmbox run` of a
// short SAR search writes RUN_DIR/<trial>/recording.mcap; tests/js/verify_mcap.mjs reads it with
// @mcap/core (CRCs, indexes, statistics, JSON) and the test compares what it found with the run's
// truth.csv and events.jsonl:
//   - the contract's channels (ARCHITECTURE.md "Recordings"): /world once at t=0, /tf, and per drone of
//     truth.csv its truth, estimate, setpoint, raft and status; /log; scouts' camera frames;
//   - counts: /tf and each truth channel at record.rate_hz (10 Hz) over the simulated time; the
//     agents' status close to that (their telemetry, best effort); /log holds the run's log events;
//   - time range: from 0 to the end of truth.csv.
// The same recording replays in the built-in page (`swarmbox view`, headless Chromium). And
// `--no-record` leaves no recording; and `swarmbox run --view` serves the same channels live
// while the trial runs: Foxglove's own client (@foxglove/ws-protocol, tests/js/ws_client.mjs)
// subscribes to the running trial and receives its poses (issue #20.2).
#include <gtest/gtest.h>

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <thread>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "support/child_process.hpp"
#include "support/files.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/runner/naming.hpp"

namespace swarmbox::e2e {
namespace {

namespace fs = std::filesystem;
using swarmbox::testing::ReadWholeFile;
using swarmbox::testing::ChildProcess;
using swarmbox::testing::RunToEnd;

constexpr char kSwarmbox[] = SWARMBOX_CLI_EXE;
const std::string kTrials = std::string(SWARMBOX_SOURCE_DIR) + "/trials";
constexpr double kRateHz = 10.0;  // record.rate_hz's default

struct Channel {
  std::string schema;
  std::uint64_t count = 0;
  std::uint64_t first_ns = 0;
  std::uint64_t last_ns = 0;
};

// A count or time of verify_mcap's summary; an empty channel's first_ns/last_ns are null: 0.
std::uint64_t U(const yaml::Node* n) {
  if (n == nullptr || !n->is_scalar()) return 0;
  auto v = n->AsDouble();
  return v ? static_cast<std::uint64_t>(*v) : 0;
}

// A free TCP port on 127.0.0.1 (bound, read back, released: the engine binds it next).
int FreePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof(a);
  int port = 0;
  if (fd >= 0 && ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0) {
    port = ntohs(a.sin_port);
  }
  if (fd >= 0) ::close(fd);
  return port;
}

class RecordingE2e : public ::testing::Test {
 protected:
  void SetUp() override {
    auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
    ASSERT_TRUE(client) << "this test needs a Docker engine: " << client.error().ToString();
    api_ = std::move(*client);
    ASSERT_TRUE(std::string(SWARMBOX_NODE).find("NOTFOUND") == std::string::npos)
        << "node was not found at configure time: install nodejs (scripts/setup.sh) and configure again";
    ASSERT_TRUE(fs::exists(std::string(SWARMBOX_JS_DIR) + "/node_modules/@mcap/core"))
        << "run `npm ci` in " << SWARMBOX_JS_DIR << " (scripts/setup.sh does)";
    dir_ = fs::temp_directory_path() / ("swarmbox-recording-e2e-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (api_ != nullptr) {
      for (const std::string& id : run_ids_) {
        docker::LabelSelector run;
        run.equals[std::string(docker::kLabelRun)] = id;
        (void)docker::RemoveLabelled(*api_, run, /*include_images=*/false);
      }
    }
    fs::remove_all(dir_);
  }

  std::vector<std::string> RunArgv(const std::string& id, const std::string& sim_timeout) const {
    return {kSwarmbox, "run", kTrials + "/sar_search.yaml", "--out", dir_.string(), "--run-id", id, "--quiet",
            "--set", "seed=7", "--set", "timeout.sim=" + sim_timeout, "--set", "physics.rtf=0"};
  }

  fs::path Run(const std::string& sim_timeout, const std::vector<std::string>& extra) {
    const std::string id = runner::NewRunId();
    run_ids_.push_back(id);
    std::vector<std::string> argv = RunArgv(id, sim_timeout);
    argv.insert(argv.end(), extra.begin(), extra.end());
    auto done = RunToEnd(argv, std::chrono::minutes(10), dir_.string());
    EXPECT_TRUE(done) << done.error().ToString();
    if (done) {
      EXPECT_TRUE(done->code == 0 || done->code == 1) << "exit " << done->code << "\n" << done->err;
    }
    return dir_ / runner::TrialDirName("sar-search", id);
  }

  // The recording of a real trial replays in the built-in page: `swarmbox view RUN_DIR` serves it,
  // headless Chromium loads the page (tests/js/page_check.mjs: the drones appear, the slider moves
  // them, a drone's camera frame shows, an event click jumps to its time) and saves a screenshot.
  void ExpectThePageReplays(const fs::path& trial) {
    const int port = FreePort();
    ASSERT_GT(port, 0);
    const std::string out = (dir_ / "view.out").string();
    auto view = ChildProcess::Spawn({kSwarmbox, "view", trial.string(), "--addr", "127.0.0.1:" + std::to_string(port)},
                                    out, out);
    ASSERT_TRUE(view) << view.error().ToString();
    const std::string url = "http://127.0.0.1:" + std::to_string(port) + "/";
    for (int i = 0; i < 100 && ReadWholeFile(out).find("view: ") == std::string::npos && view->running(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    const std::string shot = (dir_ / "view.png").string();
    auto page = RunToEnd({SWARMBOX_NODE, std::string(SWARMBOX_JS_DIR) + "/page_check.mjs", url, "--drones", "4",
                          "--screenshot", shot, "--timeout-ms", "90000"},
                         std::chrono::minutes(3), dir_.string());
    ASSERT_TRUE(page) << page.error().ToString();
    EXPECT_EQ(page->code, 0) << page->out.substr(0, 3000) << "\n" << page->err << "\nview: " << ReadWholeFile(out);
    EXPECT_TRUE(fs::exists(shot));
    EXPECT_EQ(view->Stop(std::chrono::seconds(5)), 0) << ReadWholeFile(out);
  }

  std::unique_ptr<docker::DockerClient> api_;
  fs::path dir_;
  std::vector<std::string> run_ids_;
};

TEST_F(RecordingE2e, SarSearchRecordingMatchesTruthAndEvents) {
  // 30 simulated s: the scouts climb for about 17 s before they fly out to their sectors, and the
  // page check wants them to have moved across the map by 75 % of the recording.
  const fs::path trial = Run("30s", {});
  const fs::path mcap = trial / "recording.mcap";
  ASSERT_TRUE(fs::exists(mcap)) << "no recording in " << trial;

  auto verified = RunToEnd({SWARMBOX_NODE, std::string(SWARMBOX_JS_DIR) + "/verify_mcap.mjs", mcap.string()},
                           std::chrono::minutes(3), dir_.string());
  ASSERT_TRUE(verified) << verified.error().ToString();
  ASSERT_EQ(verified->code, 0) << verified->err;
  auto summary = yaml::Parse(verified->out, "verify_mcap");
  ASSERT_TRUE(summary) << summary.error().ToString() << "\n" << verified->out.substr(0, 2000);
  std::map<std::string, Channel> channels;
  for (const yaml::Node& c : summary->Find("channels")->items()) {
    channels[c.Find("topic")->scalar()] = {c.Find("schema_name")->scalar(), U(c.Find("count")), U(c.Find("first_ns")),
                                          U(c.Find("last_ns"))};
  }
  std::cout << "[recording] " << fs::file_size(mcap) << " bytes, " << U(summary->Find("message_count"))
            << " messages, " << channels.size() << " channels, " << U(summary->Find("start_ns")) << ".."
            << U(summary->Find("end_ns")) << " ns" << std::endl;

  // truth.csv: the drones and the simulated time covered.
  std::set<std::string> drones;
  double last_t_s = 0;
  {
    std::istringstream csv(ReadWholeFile((trial / "truth.csv").string()));
    std::string line;
    std::getline(csv, line);
    ASSERT_EQ(line.rfind("t_s,drone,", 0), 0u) << line;
    while (std::getline(csv, line)) {
      const auto c1 = line.find(',');
      const auto c2 = line.find(',', c1 + 1);
      if (c1 == std::string::npos || c2 == std::string::npos) continue;
      last_t_s = std::max(last_t_s, std::stod(line.substr(0, c1)));
      drones.insert(line.substr(c1 + 1, c2 - c1 - 1));
    }
  }
  ASSERT_EQ(drones.size(), 4u);
  ASSERT_GT(last_t_s, 15.0);

  // The channels and their schemas.
  auto expect_channel = [&](const std::string& topic, const std::string& schema) -> const Channel* {
    auto it = channels.find(topic);
    EXPECT_NE(it, channels.end()) << topic << " missing";
    if (it == channels.end()) return nullptr;
    EXPECT_EQ(it->second.schema, schema) << topic;
    return &it->second;
  };
  const Channel* world = expect_channel("/world", "foxglove.SceneUpdate");
  if (world != nullptr) {
    EXPECT_EQ(world->count, 1u);
    EXPECT_EQ(world->first_ns, 0u);
  }
  // Truth at 10 Hz from t = 0 to the end of truth.csv.
  const double expected_poses = std::floor(last_t_s * kRateHz) + 1;
  const Channel* tf = expect_channel("/tf", "foxglove.FrameTransforms");
  if (tf != nullptr) {
    EXPECT_NEAR(static_cast<double>(tf->count), expected_poses, 2.0);
    EXPECT_EQ(tf->first_ns, 0u);
    EXPECT_NEAR(static_cast<double>(tf->last_ns) * 1e-9, last_t_s, 0.2);
  }
  EXPECT_EQ(U(summary->Find("start_ns")), 0u);
  EXPECT_NEAR(static_cast<double>(U(summary->Find("end_ns"))) * 1e-9, last_t_s, 0.5);
  int cameras = 0;
  for (const std::string& d : drones) {
    const std::string base = "/drones/" + d + "/";
    if (const Channel* truth = expect_channel(base + "truth", "swarmbox.DroneTruth")) {
      EXPECT_NEAR(static_cast<double>(truth->count), expected_poses, 2.0) << d;
    }
    // The agents' telemetry at the same rate, best effort (the first ones may precede discovery).
    for (const char* what : {"estimate", "setpoint", "status"}) {
      auto it = channels.find(base + what);
      ASSERT_NE(it, channels.end()) << base + what;
      EXPECT_GE(static_cast<double>(it->second.count), 0.8 * expected_poses) << base + what;
    }
    EXPECT_EQ(channels[base + "estimate"].schema, "foxglove.PoseInFrame");
    EXPECT_EQ(channels[base + "raft"].schema, "swarmbox.RaftState");
    EXPECT_GT(channels[base + "raft"].count, 0u) << d;
    if (channels.count(base + "camera") > 0 && channels[base + "camera"].count > 0) ++cameras;
  }
  EXPECT_GE(cameras, 1) << "no camera frames recorded";
  expect_channel("/radio/links", "swarmbox.Links");
  EXPECT_GT(channels["/radio/links"].count, 0u);
  EXPECT_GT(channels["/mission/sectors"].count, 0u) << "the leader's plan";

  // /log: the run's log events (those of the drones and the physics server in events.jsonl, up to
  // the recording's end); the agents' reach it with their telemetry, best effort.
  std::uint64_t events = 0;
  {
    std::istringstream in(ReadWholeFile((trial / "events.jsonl").string()));
    std::string line;
    const std::uint64_t end_ns = U(summary->Find("end_ns"));
    while (std::getline(in, line)) {
      auto e = yaml::Parse(line, "events.jsonl");
      if (!e || e->Find("t") == nullptr || e->Find("node") == nullptr) continue;
      const std::string node = e->Find("node")->scalar();
      if (node != "physics" && drones.count(node) == 0) continue;
      if (*e->Find("t")->AsDouble() * 1e9 > static_cast<double>(end_ns)) continue;
      ++events;
    }
  }
  const Channel* log = expect_channel("/log", "foxglove.Log");
  ASSERT_GT(events, 20u);
  if (log != nullptr) {
    std::cout << "[recording] /log " << log->count << " messages, events.jsonl " << events << " events" << std::endl;
    EXPECT_GE(static_cast<double>(log->count), 0.9 * static_cast<double>(events));
  }
  ExpectThePageReplays(trial);
}

TEST_F(RecordingE2e, NoRecordLeavesNone) {
  const fs::path trial = Run("5s", {"--no-record"});
  EXPECT_TRUE(fs::exists(trial / "truth.csv")) << trial;
  EXPECT_FALSE(fs::exists(trial / "recording.mcap"));
}

TEST_F(RecordingE2e, TheLiveViewServesARunningTrialToFoxglovesClient) {
  const int port = FreePort();
  ASSERT_GT(port, 0);
  const std::string id = runner::NewRunId();
  run_ids_.push_back(id);
  std::vector<std::string> argv = RunArgv(id, "30s");
  argv.insert(argv.end(), {"--view", "127.0.0.1:" + std::to_string(port)});
  const std::string out = (dir_ / "run.out").string();
  auto run = ChildProcess::Spawn(argv, out, out);
  ASSERT_TRUE(run) << run.error().ToString();

  // The client connects once the physics server listens (the engine publishes its port when the
  // container starts): until then it exits 2 (no connection), and is started again.
  const std::string url = "ws://127.0.0.1:" + std::to_string(port);
  std::optional<testing::Finished> got;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(5);
  while (std::chrono::steady_clock::now() < deadline && run->running()) {
    auto client = RunToEnd({SWARMBOX_NODE, std::string(SWARMBOX_JS_DIR) + "/ws_client.mjs", url, "--want", "/tf=20",
                            "--want", "/log=1", "--timeout-ms", "120000"},
                           std::chrono::minutes(3), dir_.string());
    ASSERT_TRUE(client) << client.error().ToString();
    if (client->code != 2) {
      got = *client;
      break;
    }
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  const std::optional<int> code = run->Wait(std::chrono::minutes(8));
  const std::string printed = ReadWholeFile(out);
  ASSERT_TRUE(got) << "the client never reached " << url << " while the trial ran:\n" << printed;
  EXPECT_EQ(got->code, 0) << got->err;
  auto doc = yaml::Parse(got->out, "ws_client");
  ASSERT_TRUE(doc) << doc.error().ToString();
  const yaml::Node* tf = doc->Find("received") != nullptr ? doc->Find("received")->Find("/tf") : nullptr;
  ASSERT_NE(tf, nullptr) << got->out.substr(0, 2000);
  EXPECT_GE(tf->items().size(), 20u);
  // The poses are the trial's drones, as the recording has them.
  const std::string first = yaml::EmitJson(tf->items().front());
  EXPECT_NE(first.find("scout_1"), std::string::npos) << first.substr(0, 500);
  ASSERT_TRUE(code.has_value()) << "swarmbox run did not end";
  EXPECT_TRUE(*code == 0 || *code == 1) << "exit " << *code << "\n" << printed;
  EXPECT_NE(printed.find("view: http://127.0.0.1:" + std::to_string(port) + "/"), std::string::npos) << printed;
}

}  // namespace
}  // namespace swarmbox::e2e
