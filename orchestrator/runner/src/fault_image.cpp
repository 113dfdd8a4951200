#include "swarmbox/runner/fault_image.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/standard_images.hpp"
#include "swarmbox/images/tag_cache.hpp"

namespace swarmbox::runner {

namespace fs = std::filesystem;

namespace {

constexpr char kNetemd[] = "swarmbox-netemd";

bool IsExecutable(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
}

}  // namespace

Result<std::string> FindNetemd(const std::string& explicit_path) {
  if (!explicit_path.empty()) {
    if (IsExecutable(explicit_path)) return fs::absolute(explicit_path).lexically_normal().string();
    return Error(ErrorCode::kNotFound, "swarmbox-netemd: not an executable file", explicit_path);
  }
  std::vector<fs::path> candidates;
  if (const char* dir = std::getenv("SWARMBOX_BIN_DIR"); dir != nullptr && *dir != '\0') {
    candidates.push_back(fs::path(dir) / kNetemd);
  }
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    fs::path dir = self.parent_path();
    for (int up = 0; up < 4 && !dir.empty(); ++up, dir = dir.parent_path()) {
      candidates.push_back(dir / "orchestrator" / "faults" / kNetemd);
      if (dir == dir.parent_path()) break;
    }
  }
  if (const char* path = std::getenv("PATH"); path != nullptr) {
    std::string_view rest = path;
    while (!rest.empty()) {
      const auto colon = rest.find(':');
      const std::string_view dir = rest.substr(0, colon);
      if (!dir.empty()) candidates.push_back(fs::path(dir) / kNetemd);
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
               "cannot find swarmbox-netemd for the fault sidecar image (looked in " + looked +
                   "); build the target swarmbox-netemd or set SWARMBOX_BIN_DIR");
}

Result<std::string> EnsureFaultsImage(docker::DockerApi& api, const std::string& netemd_binary,
                                      const std::function<void(std::string_view)>& progress) {
  auto spec = images::FaultSidecarImage(netemd_binary);
  if (!spec) return spec.error().Context("fault sidecar image");
  const images::TagCache cache(images::DefaultTagCacheDir());
  auto built = images::EnsureImage(api, *spec, progress, nullptr, &cache);
  if (!built) return built.error().Context("image swarmbox/faults");
  return built->tag;
}

}  // namespace swarmbox::runner
