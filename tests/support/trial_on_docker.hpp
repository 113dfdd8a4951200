// TrialOnDocker: the Docker side of an e2e test that runs a trial on the real engine with this
// build's programs (the fault e2e fixtures): the engine connection, the physics and agent images
// (and the fault sidecar image when netemd is given) built from the programs, RunOptions for a
// fresh run id writing into a fresh folder, and, when it goes away, the removal of everything
// labelled with the run. Library swarmbox_docker_trial_test_support (links swarmbox::runner).
//
//   testing::TrialOnDocker engine;
//   const Status ready = engine.Prepare("fault-e2e", {SWARMBOX_PHYSICS_BIN, SWARMBOX_AGENT_BIN,
//                                                     SWARMBOX_NETEMD_BIN});
//   ASSERT_TRUE(ready) << ready.error().ToString();
//   auto run = runner::RunTrialSpec(spec, engine.api(), clock, engine.options());
//   auto containers = engine.api().ListContainers(engine.mine(), /*all=*/true);   // none left
#pragma once

#include <memory>
#include <string>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/runner/runner.hpp"

namespace swarmbox::testing {

class TrialOnDocker {
 public:
  struct Programs {
    std::string physics;  // swarmbox-physics of this build
    std::string agent;    // swarmbox-agent
    std::string netemd;   // swarmbox-netemd: the fault sidecar image too ("" = not needed)
  };

  TrialOnDocker() = default;
  ~TrialOnDocker();  // removes every container and network labelled with the run
  TrialOnDocker(const TrialOnDocker&) = delete;
  TrialOnDocker& operator=(const TrialOnDocker&) = delete;

  // Connects to the local engine ("this test needs a Docker engine: ..." when there is none),
  // builds the images, and fills options(): out_dir <tmp>/swarmbox-<name> (emptied), a new run id,
  // the images, host "<name>-local", poll 50 ms.
  Status Prepare(const std::string& name, const Programs& programs);

  docker::DockerApi& api() { return *client_; }
  runner::RunOptions& options() { return options_; }
  // Selects what is labelled with the run.
  const docker::LabelSelector& mine() const { return mine_; }

 private:
  std::unique_ptr<docker::DockerClient> client_;
  runner::RunOptions options_;
  docker::LabelSelector mine_;
};

}  // namespace swarmbox::testing
