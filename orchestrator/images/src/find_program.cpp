#include "swarmbox/images/find_program.hpp"

#include <unistd.h>

#include <cstdlib>

namespace swarmbox::images {

namespace fs = std::filesystem;

namespace {

bool IsExecutable(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
}

}  // namespace

fs::path SelfDir() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : self.parent_path();
}

Result<std::string> FindProgram(std::string_view name, const std::string& explicit_path,
                                const std::vector<fs::path>& preferred, std::string_view hint) {
  if (!explicit_path.empty()) {
    if (IsExecutable(explicit_path)) return fs::absolute(explicit_path).lexically_normal().string();
    return Error(ErrorCode::kNotFound, std::string(name) + ": not an executable file", explicit_path);
  }
  std::vector<fs::path> candidates;
  if (const char* dir = std::getenv("SWARMBOX_BIN_DIR"); dir != nullptr && *dir != '\0') {
    candidates.push_back(fs::path(dir) / name);
  }
  candidates.insert(candidates.end(), preferred.begin(), preferred.end());
  // Installed programs sit side by side in <prefix>/bin (cmake --install).
  if (const fs::path self = SelfDir(); !self.empty()) candidates.push_back(self / name);
  if (const char* path = std::getenv("PATH"); path != nullptr) {
    std::string_view rest = path;
    while (!rest.empty()) {
      const auto colon = rest.find(':');
      const std::string_view dir = rest.substr(0, colon);
      if (!dir.empty()) candidates.push_back(fs::path(dir) / name);
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
               "cannot find " + std::string(name) + " (looked in " + looked + "); " + std::string(hint));
}

}  // namespace swarmbox::images
