// A user component on the real engine (issue #24, "Done when"): trials/components/probe.yaml run
// by the built `swarmbox run` as a user runs it. The component, swarmbox_component_probe from this
// build, is packed into its own registry-free image, started before the physics server, waited for
// on its readiness line, stopped with the trial; the file it wrote comes back to
// <trial>/components/probe/hello.txt (written at the start and at the stop: collected after the
// stop). Its log is kept like every other, its container was labelled role=component, and
// afterwards nothing labelled with the run is left.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "support/child_process.hpp"
#include "support/files.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/runner/naming.hpp"

namespace swarmbox::e2e {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using swarmbox::testing::ReadWholeFile;
using swarmbox::testing::RunToEnd;

constexpr char kSwarmbox[] = SWARMBOX_CLI_EXE;

// Removes what the run labelled and the scratch folder, however the test ends.
struct RunCleanup {
  docker::DockerApi& api;
  docker::LabelSelector selector;
  fs::path dir;
  ~RunCleanup() {
    (void)docker::RemoveLabelled(api, selector, /*include_images=*/false);
    fs::remove_all(dir);
  }
};

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << "cannot write " << path;
}
const std::string kTrial = std::string(SWARMBOX_SOURCE_DIR) + "/trials/components/probe.yaml";

TEST(ComponentE2e, AUserComponentRunsAndItsCollectedFileComesBack) {
  auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
  ASSERT_TRUE(client) << "this test needs a Docker engine: " << client.error().ToString();
  docker::DockerApi& api = **client;
  const fs::path dir = fs::temp_directory_path() / ("swarmbox-component-e2e-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string run_id = runner::NewRunId();
  docker::LabelSelector mine;
  mine.equals[std::string(docker::kLabelRun)] = run_id;
  const RunCleanup cleanup{api, mine, dir};

  const std::string set_program = std::string("components.probe.program=") + SWARMBOX_PROBE_EXE;
  // The file validates with this build's program.
  auto valid = RunToEnd({kSwarmbox, "validate", kTrial, "--set", set_program}, std::chrono::minutes(1), dir.string());
  ASSERT_TRUE(valid) << valid.error().ToString();
  EXPECT_EQ(valid->code, 0) << valid->out << valid->err;

  auto done = RunToEnd({kSwarmbox, "run", kTrial, "--out", dir.string(), "--run-id", run_id, "--set", set_program},
                       std::chrono::minutes(8), dir.string());
  ASSERT_TRUE(done) << done.error().ToString();
  std::cout << done->out << done->err;
  EXPECT_EQ(done->code, 0) << done->err;

  const fs::path trial_dir = dir / runner::TrialDirName("probe", run_id);
  auto result = yaml::Parse(ReadWholeFile((trial_dir / "result.json").string()), "result.json");
  ASSERT_TRUE(result) << result.error().ToString();
  EXPECT_EQ(result->Find("outcome")->scalar(), "success") << ReadWholeFile((trial_dir / "result.json").string());

  // The collected file, as the program left it at its stop.
  const std::string hello = ReadWholeFile((trial_dir / "components" / "probe" / "hello.txt").string());
  EXPECT_THAT(hello, HasSubstr("started trial=probe\n"));
  EXPECT_THAT(hello, HasSubstr("stopped signal=15\n"));
  // Its log like the others', its readiness line first, its stop last; events.jsonl has both.
  const std::string log = ReadWholeFile((trial_dir / "logs" / "probe.log").string());
  EXPECT_THAT(log, HasSubstr("event=probe_ready out=/tmp/probe/hello.txt"));
  EXPECT_THAT(log, HasSubstr("event=probe_stopped signal=15"));
  const std::string events = ReadWholeFile((trial_dir / "events.jsonl").string());
  EXPECT_THAT(events, HasSubstr("\"component\":\"probe\""));
  EXPECT_THAT(events, HasSubstr("\"event\":\"probe_ready\""));
  // It started before the physics server (its priority 0 < the drones' 100).
  EXPECT_LT(events.find("\"event\":\"run\",\"target\":\"probe\""), events.find("\"event\":\"run\",\"target\":\"physics\""));
  const yaml::Node* components = result->Find("components");
  ASSERT_NE(components, nullptr);
  bool reported = false;
  for (const yaml::Node& c : components->items()) {
    if (c.Find("name") != nullptr && c.Find("name")->scalar() == "probe") {
      reported = true;
      EXPECT_EQ(c.Find("exit_code")->scalar(), "0");
    }
  }
  EXPECT_TRUE(reported);
  // Its image is the packed one.
  docker::LabelSelector packed;
  packed.equals["swarmbox.image"] = "swarmbox/component";
  auto images = api.ListImages(packed);
  ASSERT_TRUE(images) << images.error().ToString();
  EXPECT_FALSE(images->empty());

  // Nothing labelled with the run is left.
  auto containers = api.ListContainers(mine, /*all=*/true);
  ASSERT_TRUE(containers) << containers.error().ToString();
  EXPECT_TRUE(containers->empty());
  auto networks = api.ListNetworks(mine);
  ASSERT_TRUE(networks) << networks.error().ToString();
  EXPECT_TRUE(networks->empty());
}


// A component whose image the engine builds from the trial's Dockerfile (its folder is the build
// context). Nothing can be pulled here, so the Dockerfile starts FROM scratch and copies the probe
// linked statically; the trial lives in a scratch `trials/` folder whose worlds and airframes are
// the shipped ones (and its radio profiles).
TEST(ComponentE2e, AComponentBuiltFromADockerfileRunsAndItsFileComesBack) {
  auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
  ASSERT_TRUE(client) << "this test needs a Docker engine: " << client.error().ToString();
  docker::DockerApi& api = **client;
  const fs::path dir = fs::temp_directory_path() / ("swarmbox-dockerfile-e2e-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path trials = dir / "trials";
  fs::create_directories(trials / "components" / "built");
  for (const char* shared : {"worlds", "airframes", "radios"}) {
    fs::create_directory_symlink(fs::path(SWARMBOX_SOURCE_DIR) / "trials" / shared, trials / shared);
  }
  fs::copy_file(SWARMBOX_STATIC_PROBE_EXE, trials / "components" / "built" / "probe");
  WriteText((trials / "components" / "built" / "Dockerfile").string(),
                                    "FROM scratch\nCOPY probe /probe\nENTRYPOINT [\"/probe\"]\n");
  const fs::path trial = trials / "components" / "built.yaml";
  WriteText(trial.string(), R"(name: built
seed: 1
world: worlds/open_field.yaml
physics: {rtf: 0}
drones:
  - {name: scout_1, airframe: x500, pose: [0, 0, 0]}
mission: {kind: plan, plan: "takeoff:3,hover:2,land"}
components:
  - {name: built, dockerfile: built/Dockerfile, args: [--out, /hello.txt], priority: 0,
     ready: "event=probe_ready", collect: [/hello.txt]}
end:
  - {on: "event=plan_complete", outcome: success}
timeout: {sim: 60s, wall: 5m, outcome: timeout}
)");
  const std::string run_id = runner::NewRunId();
  docker::LabelSelector mine;
  mine.equals[std::string(docker::kLabelRun)] = run_id;
  const RunCleanup cleanup{api, mine, dir};

  auto done = RunToEnd({kSwarmbox, "run", trial.string(), "--out", (dir / "runs").string(), "--run-id", run_id},
                       std::chrono::minutes(8), dir.string());
  ASSERT_TRUE(done) << done.error().ToString();
  std::cout << done->out << done->err;
  EXPECT_EQ(done->code, 0) << done->err;
  const fs::path trial_dir = dir / "runs" / runner::TrialDirName("built", run_id);
  const std::string hello = ReadWholeFile((trial_dir / "components" / "built" / "hello.txt").string());
  EXPECT_THAT(hello, HasSubstr("started trial="));
  EXPECT_THAT(hello, HasSubstr("stopped signal=15\n"));
  EXPECT_THAT(ReadWholeFile((trial_dir / "logs" / "built.log").string()), HasSubstr("event=probe_ready out=/hello.txt"));
  auto containers = api.ListContainers(mine, /*all=*/true);
  ASSERT_TRUE(containers) << containers.error().ToString();
  EXPECT_TRUE(containers->empty());
}

}  // namespace
}  // namespace swarmbox::e2e
