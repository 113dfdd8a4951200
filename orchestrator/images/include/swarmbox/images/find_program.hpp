#pragma once
// Finding the host-built programs that images pack (swarmbox-physics, swarmbox-agent,
// swarmbox-netemd) on the machine that runs the orchestrator.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::images {

// The directory of the running executable (/proc/self/exe), or empty if it cannot be read.
std::filesystem::path SelfDir();

// `explicit_path` when it is given (kNotFound if it is not an executable file). Otherwise the first
// executable among $SWARMBOX_BIN_DIR/<name>, then `preferred` (e.g. places in the build tree next
// to the running executable), then SelfDir()/<name> (an installed swarmbox finds its companions in
// its own <prefix>/bin), then every $PATH entry. kNotFound lists every place looked in and ends
// with `hint` (how to build or name the program).
Result<std::string> FindProgram(std::string_view name, const std::string& explicit_path,
                                const std::vector<std::filesystem::path>& preferred,
                                std::string_view hint);

}  // namespace swarmbox::images
