// swarmbox images [--no-faults] [-q] [--json]: build (only what is missing) the registry-free
// images on the engine ($DOCKER_HOST).
#include <iostream>

#include "commands.hpp"
#include "connect_engine.hpp"
#include "json_out.hpp"
#include "program_images.hpp"
#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/standard_images.hpp"
#include "swarmbox/runner/fault_image.hpp"

namespace swarmbox::cli {

namespace {

// An image to ensure, or why its spec could not be made (a program not found).
struct Wanted {
  const char* what;
  Result<images::ImageSpec> spec;
};

std::vector<Wanted> WantedImages(const ImagesArgs& args) {
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
  return wanted;
}

// Each image ensured, printed (a line, or an item of `listed` for --json); failures on stderr
// and in `listed`. Returns the number of failures.
int EnsureWanted(const ImagesArgs& args, docker::DockerClient& client, std::vector<Wanted>& wanted,
                 yaml::Node* listed) {
  auto progress = [&](std::string_view line) {
    if (!args.quiet) std::cerr << "  " << line << "\n";
  };
  int failures = 0;
  auto failed = [&](const char* what, const Error& e) {
    std::cerr << what << ": " << e.ToString() << "\n";
    ++failures;
    yaml::Node item = yaml::Node::Mapping();
    item.Set("image", json::Str(what));
    item.Set("error", json::Str(e.ToString()));
    listed->Append(std::move(item));
  };
  // Remembers the tags, so the next `swarmbox run` does not pack the same programs again.
  const images::TagCache cache(images::DefaultTagCacheDir());
  for (Wanted& w : wanted) {
    if (!w.spec) {
      failed(w.what, w.spec.error());
      continue;
    }
    auto r = images::EnsureImage(client, *w.spec, progress, nullptr, &cache);
    if (!r) {
      failed(w.what, r.error());
      continue;
    }
    if (args.json) {
      yaml::Node item = yaml::Node::Mapping();
      item.Set("image", json::Str(w.what));
      item.Set("tag", json::Str(r->tag));
      item.Set("built", json::Bool(r->built));
      item.Set("size_bytes", json::Int(static_cast<std::int64_t>(r->image_size_bytes)));
      listed->Append(std::move(item));
    } else {
      std::cout << r->tag << (r->built ? "  built" : "  present") << "  "
                << r->image_size_bytes / (1024 * 1024) << " MiB\n";
    }
  }
  return failures;
}

}  // namespace

int ImagesCommand(const ImagesArgs& args) {
  EngineConnection engine = ConnectEngineOrPrintError("images");
  if (!engine.client) return engine.exit_code;
  docker::DockerClient& client = *engine.client;
  std::vector<Wanted> wanted = WantedImages(args);
  yaml::Node listed = yaml::Node::Sequence();  // --json
  const int failures = EnsureWanted(args, client, wanted, &listed);
  const int code = failures == 0 ? kExitOk : kExitInfrastructure;
  if (args.json) {
    yaml::Node o = yaml::Node::Mapping();
    o.Set("engine", json::Str(client.transport().endpoint()));
    o.Set("images", std::move(listed));
    o.Set("exit_code", json::Int(code));
    json::Print(o);
  }
  return code;
}

}  // namespace swarmbox::cli
