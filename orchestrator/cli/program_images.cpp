#include "program_images.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/image_context.hpp"
#include "swarmbox/images/standard_images.hpp"
#include "swarmbox/images/tag_cache.hpp"

namespace swarmbox::cli {

namespace fs = std::filesystem;

namespace {

bool IsExecutable(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
}

std::string SelfDir() {
  std::error_code ec;
  fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : self.parent_path().string();
}

}  // namespace

Result<std::string> FindProgram(std::string_view program, const std::string& explicit_path) {
  if (!explicit_path.empty()) {
    if (IsExecutable(explicit_path)) return fs::absolute(explicit_path).string();
    return Error(ErrorCode::kNotFound, "not an executable file", explicit_path);
  }
  std::vector<fs::path> candidates;
  if (const char* dir = std::getenv("SWARMBOX_BIN_DIR"); dir != nullptr && *dir != '\0') {
    candidates.push_back(fs::path(dir) / program);
  }
  if (const std::string self = SelfDir(); !self.empty()) {
    const fs::path build = fs::path(self) / ".." / "..";
    const std::string component = program == "swarmbox-physics" ? "physics_server" : "agent";
    candidates.push_back(build / component / "app" / program);
    candidates.push_back(build / component / program);
    candidates.push_back(build / "bin" / program);
  }
  if (const char* path = std::getenv("PATH"); path != nullptr) {
    std::string_view rest = path;
    while (!rest.empty()) {
      const auto colon = rest.find(':');
      const std::string_view dir = rest.substr(0, colon);
      if (!dir.empty()) candidates.push_back(fs::path(dir) / program);
      if (colon == std::string_view::npos) break;
      rest = rest.substr(colon + 1);
    }
  }
  std::string looked;
  for (const fs::path& c : candidates) {
    if (IsExecutable(c)) return c.lexically_normal().string();
    looked += (looked.empty() ? "" : ", ") + c.lexically_normal().string();
  }
  return Error(ErrorCode::kNotFound,
               "cannot find " + std::string(program) + " (looked in " + looked +
                   "); build it, or pass its path with --" +
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
