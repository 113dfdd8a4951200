// The project's docs stand alone: every relative link in every *.md of the repository (README,
// ARCHITECTURE, STYLE, BENCHMARKS, the folder READMEs) resolves to a file or folder inside the
// repository, and a link to a heading (`#anchor`, `FILE.md#anchor`) names a heading that exists.
// A user who cloned the project follows every link; nothing points at a sibling checkout.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>

#include "markdown.hpp"
#include "support/files.hpp"

namespace swarmbox::docs {
namespace {

namespace fs = std::filesystem;

const fs::path kRoot = fs::path(SWARMBOX_SOURCE_DIR).lexically_normal();

// Build trees (build/, build-asan/, any folder with a CMakeCache.txt), VCS and hidden folders,
// trial outputs and installed npm packages (tests/js/node_modules, git-ignored) are not the
// project's docs.
bool Skipped(const fs::path& dir) {
  const std::string name = dir.filename().string();
  return name.empty() || name[0] == '.' || name.rfind("build", 0) == 0 || name == "runs" ||
         name == "node_modules" ||
         fs::exists(dir / "CMakeCache.txt");
}

std::vector<fs::path> MarkdownFiles() {
  std::vector<fs::path> files;
  for (auto it = fs::recursive_directory_iterator(kRoot); it != fs::recursive_directory_iterator(); ++it) {
    if (it->is_directory() && Skipped(it->path())) {
      it.disable_recursion_pending();
    } else if (it->is_regular_file() && it->path().extension() == ".md") {
      files.push_back(it->path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

bool External(const std::string& target) {
  const std::size_t colon = target.find(':');
  const std::size_t slash = target.find('/');
  return colon != std::string::npos && (slash == std::string::npos || colon < slash);  // a scheme
}

// '%20' and friends as the browser decodes them.
std::string PercentDecoded(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size()) {
      out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

TEST(RepositoryDocs, FindsTheProjectsMarkdownFiles) {
  const std::vector<fs::path> files = MarkdownFiles();
  for (const char* expected : {"README.md", "ARCHITECTURE.md", "STYLE.md", "BENCHMARKS.md"}) {
    EXPECT_NE(std::find(files.begin(), files.end(), kRoot / expected), files.end()) << expected;
  }
}

TEST(RepositoryDocs, EveryRelativeLinkResolvesInsideTheRepository) {
  std::map<fs::path, std::set<std::string>> anchors;  // per Markdown file, read once
  auto anchors_of = [&](const fs::path& md) -> const std::set<std::string>& {
    auto it = anchors.find(md);
    if (it == anchors.end()) it = anchors.emplace(md, HeadingAnchors(testing::ReadWholeFile(md.string()))).first;
    return it->second;
  };
  std::size_t checked = 0;
  for (const fs::path& file : MarkdownFiles()) {
    const std::string rel_file = file.lexically_relative(kRoot).string();
    for (const MarkdownLink& link : MarkdownLinks(testing::ReadWholeFile(file.string()))) {
      if (External(link.target)) continue;
      ++checked;
      const std::string where = rel_file + ":" + std::to_string(link.line) + ": link '" + link.target + "'";
      const std::size_t hash = link.target.find('#');
      const std::string path_part = PercentDecoded(link.target.substr(0, hash));
      const std::string anchor = hash == std::string::npos ? "" : link.target.substr(hash + 1);
      if (!path_part.empty() && path_part[0] == '/') {
        ADD_FAILURE() << where << " is an absolute path: it does not resolve in a clone of the project";
        continue;
      }
      const fs::path resolved = path_part.empty() ? file : (file.parent_path() / path_part).lexically_normal();
      const fs::path inside = resolved.lexically_relative(kRoot);
      if (inside.empty() || *inside.begin() == "..") {
        ADD_FAILURE() << where << " points outside the repository (" << resolved.string() << ")";
        continue;
      }
      if (!fs::exists(resolved)) {
        ADD_FAILURE() << where << ": no such file or folder in the repository (" << inside.string() << ")";
        continue;
      }
      if (!anchor.empty() && resolved.extension() == ".md" && anchors_of(resolved).count(anchor) == 0) {
        ADD_FAILURE() << where << ": " << inside.string() << " has no heading with anchor #" << anchor;
      }
    }
  }
  EXPECT_GT(checked, 10u) << "the docs' links were not found: is the Markdown reader broken?";
}

}  // namespace
}  // namespace swarmbox::docs
