#include "program_images.hpp"

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/find_program.hpp"
#include "swarmbox/images/image_context.hpp"
#include "swarmbox/images/standard_images.hpp"
#include "swarmbox/images/tag_cache.hpp"

namespace swarmbox::cli {

namespace fs = std::filesystem;

Result<std::string> FindProgram(std::string_view program, const std::string& explicit_path) {
  std::vector<fs::path> build_tree;  // swarmbox sits in <build>/orchestrator/cli
  if (const fs::path self = images::SelfDir(); !self.empty()) {
    const fs::path build = self / ".." / "..";
    const std::string component = program == "swarmbox-physics" ? "physics_server" : "agent";
    build_tree = {build / component / "app" / program, build / component / program,
                  build / "bin" / program};
  }
  return images::FindProgram(program, explicit_path, build_tree,
                             std::string("build it, or pass its path with --") +
                                 (program == "swarmbox-physics" ? "physics" : "agent") + "-bin");
}

Result<runner::Images> EnsureTrialImages(docker::DockerApi& api, const ProgramPaths& programs,
                                         const std::function<void(std::string_view)>& progress) {
  auto physics_bin = FindProgram("swarmbox-physics", programs.physics_bin);
  if (!physics_bin) return physics_bin.error();
  auto agent_bin = FindProgram("swarmbox-agent", programs.agent_bin);
  if (!agent_bin) return agent_bin.error();
  runner::Images out;
  // Unchanged programs are not packed again (their tags are remembered in the user's cache).
  const images::TagCache cache(images::DefaultTagCacheDir());
  auto physics =
      images::EnsureImage(api, images::PhysicsImage(*physics_bin), progress, nullptr, &cache);
  if (!physics) return physics.error().Context("image swarmbox/physics");
  out.physics = physics->tag;
  auto agent = images::EnsureImage(api, images::AgentImage(*agent_bin), progress, nullptr, &cache);
  if (!agent) return agent.error().Context("image swarmbox/agent");
  out.agent = agent->tag;
  return out;
}

Result<runner::Images> TrialImageTags(const ProgramPaths& programs) {
  auto physics_bin = FindProgram("swarmbox-physics", programs.physics_bin);
  if (!physics_bin) return physics_bin.error();
  auto agent_bin = FindProgram("swarmbox-agent", programs.agent_bin);
  if (!agent_bin) return agent_bin.error();
  auto physics = images::PackContext(images::PhysicsImage(*physics_bin));
  if (!physics) return physics.error().Context("packing swarmbox/physics");
  auto agent = images::PackContext(images::AgentImage(*agent_bin));
  if (!agent) return agent.error().Context("packing swarmbox/agent");
  return runner::Images{physics->tag, agent->tag};
}

}  // namespace swarmbox::cli
