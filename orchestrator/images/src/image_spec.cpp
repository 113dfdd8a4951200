#include "swarmbox/images/image_spec.hpp"

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "base_files.hpp"

namespace swarmbox::images {

void AddSwarmboxBaseFiles(ImageSpec* spec) {
  spec->inline_files["/etc/passwd"] = detail::kEtcPasswd;
  spec->inline_files["/etc/group"] = detail::kEtcGroup;
  spec->directories["/tmp"] = 01777;
}

Status AddPluginDirectory(ImageSpec* spec, const std::string& host_dir, const std::string& image_dir,
                          const std::string& suffix) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::directory_iterator it(host_dir, ec);
  if (ec) return Error(ErrorCode::kNotFound, "cannot list plugin directory: " + ec.message(), host_dir);
  std::vector<std::string> names;
  for (const fs::directory_entry& entry : it) {
    const std::string name = entry.path().filename().string();
    if (name.size() < suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
      continue;
    }
    if (!entry.is_regular_file(ec)) continue;
    names.push_back(name);
  }
  if (names.empty()) {
    return Error(ErrorCode::kNotFound, "no '*" + suffix + "' plugin in the directory", host_dir);
  }
  std::sort(names.begin(), names.end());
  for (const std::string& name : names) {
    spec->plugins.push_back(HostFile{host_dir + "/" + name, image_dir + "/" + name, 0});
  }
  return Ok{};
}

}  // namespace swarmbox::images
