#include "support/trial_on_docker.hpp"

#include <chrono>
#include <filesystem>

#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/standard_images.hpp"
#include "swarmbox/runner/fault_image.hpp"
#include "swarmbox/runner/naming.hpp"

namespace swarmbox::testing {

namespace fs = std::filesystem;

TrialOnDocker::~TrialOnDocker() {
  if (client_ && !options_.run_id.empty()) (void)docker::RemoveLabelled(*client_, mine_, false);
}

Status TrialOnDocker::Prepare(const std::string& name, const Programs& programs) {
  auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
  if (!client) return client.error().Context("this test needs a Docker engine");
  client_ = std::move(*client);
  auto physics = images::EnsureImage(*client_, images::PhysicsImage(programs.physics), {}, nullptr);
  if (!physics) return physics.error();
  auto agent = images::EnsureImage(*client_, images::AgentImage(programs.agent), {}, nullptr);
  if (!agent) return agent.error();
  if (!programs.netemd.empty()) {
    auto faults_image = runner::EnsureFaultsImage(*client_, programs.netemd, {});
    if (!faults_image) return faults_image.error();
    options_.faults_image = *faults_image;
  }
  const fs::path out = fs::temp_directory_path() / ("swarmbox-" + name);
  fs::remove_all(out);
  options_.out_dir = out.string();
  options_.run_id = runner::NewRunId();
  options_.images = {physics->tag, agent->tag};
  options_.host = name + "-local";
  options_.poll = std::chrono::milliseconds(50);
  mine_.equals[std::string(docker::kLabelRun)] = options_.run_id;
  return Ok{};
}

}  // namespace swarmbox::testing
