// What built this program: the project version, the git commit and the build type. Every program
// prints it for --version, and result.json / experiment.json / results.csv carry it as provenance
// (ARCHITECTURE.md, "Per-trial output").
//
//   const auto& b = swarmbox::Build();
//   std::cout << swarmbox::VersionLine("swarmbox") << "\n";
//   // swarmbox 0.1.0 (commit 1a2b3c4d5e6f, RelWithDebInfo)
//
// `commit` is the short hash of HEAD when the program was built, with "-dirty" when tracked files
// differed from it, or "unknown" outside a git checkout. The values are fixed at build time;
// reading them does no I/O and is thread-safe.
#pragma once

#include <string>
#include <string_view>

namespace swarmbox {

struct BuildInfo {
  std::string_view version;     // the CMake project version, e.g. "0.1.0"
  std::string_view commit;      // short git hash (+ "-dirty"), or "unknown"
  std::string_view build_type;  // CMAKE_BUILD_TYPE, e.g. "RelWithDebInfo"
};

// The build this binary came from.
const BuildInfo& Build();

// "<program> <version> (commit <commit>, <build type>)": the one --version line of every program.
std::string VersionLine(std::string_view program);

}  // namespace swarmbox
