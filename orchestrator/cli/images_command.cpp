// swarmbox images: build (only what is missing) the registry-free images on the local engine.
#include <iostream>

#include "commands.hpp"
#include "program_images.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/standard_images.hpp"
#include "swarmbox/runner/fault_image.hpp"

namespace swarmbox::cli {

int ImagesCommand(const ImagesArgs& args) {
  docker::DockerClientOptions client_options;
  client_options.socket_path = docker::DefaultSocketPath();
  auto client = docker::DockerClient::Connect(client_options);
  if (!client) {
    std::cerr << "swarmbox images: " << client.error().ToString() << "\n";
    return kExitInfrastructure;
  }
  auto progress = [](std::string_view line) { std::cerr << "  " << line << "\n"; };
  struct Wanted {
    const char* what;
    Result<images::ImageSpec> spec;
  };
  std::vector<Wanted> wanted;
  auto physics = FindProgram("swarmbox-physics", args.programs.physics_bin);
  wanted.push_back({"physics", physics ? Result<images::ImageSpec>(images::PhysicsImage(*physics))
                                       : Result<images::ImageSpec>(physics.error())});
  auto agent = FindProgram("swarmbox-agent", args.programs.agent_bin);
  wanted.push_back({"agent", agent ? Result<images::ImageSpec>(images::AgentImage(*agent))
                                   : Result<images::ImageSpec>(agent.error())});
  if (args.faults) {
    // The image the runner's fault sidecars use: tc, iptables and swarmbox-netemd.
    auto netemd = runner::FindNetemd("");
    wanted.push_back({"faults", netemd ? images::FaultSidecarImage(*netemd)
                                       : Result<images::ImageSpec>(netemd.error())});
  }
  int failures = 0;
  // Remembers the tags, so the next `swarmbox run` does not pack the same programs again.
  const images::TagCache cache(images::DefaultTagCacheDir());
  for (Wanted& w : wanted) {
    if (!w.spec) {
      std::cerr << w.what << ": " << w.spec.error().ToString() << "\n";
      ++failures;
      continue;
    }
    auto r = images::EnsureImage(**client, *w.spec, progress, nullptr, &cache);
    if (!r) {
      std::cerr << w.what << ": " << r.error().ToString() << "\n";
      ++failures;
      continue;
    }
    std::cout << r->tag << (r->built ? "  built" : "  present") << "  "
              << r->image_size_bytes / (1024 * 1024) << " MiB\n";
  }
  return failures == 0 ? kExitOk : kExitInfrastructure;
}

}  // namespace swarmbox::cli
