#include "swarmbox/runner/fault_image.hpp"

#include <filesystem>
#include <vector>

#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/find_program.hpp"
#include "swarmbox/images/standard_images.hpp"
#include "swarmbox/images/tag_cache.hpp"

namespace swarmbox::runner {

namespace fs = std::filesystem;

Result<std::string> FindNetemd(const std::string& explicit_path) {
  constexpr char kNetemd[] = "swarmbox-netemd";
  std::vector<fs::path> build_tree;  // <build>/orchestrator/faults, from up to 4 levels above
  if (fs::path dir = images::SelfDir(); !dir.empty()) {
    for (int up = 0; up < 4 && !dir.empty(); ++up, dir = dir.parent_path()) {
      build_tree.push_back(dir / "orchestrator" / "faults" / kNetemd);
      if (dir == dir.parent_path()) break;
    }
  }
  return images::FindProgram(kNetemd, explicit_path, build_tree,
                             "the fault sidecar image needs it: build the target swarmbox-netemd "
                             "or set SWARMBOX_BIN_DIR");
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
