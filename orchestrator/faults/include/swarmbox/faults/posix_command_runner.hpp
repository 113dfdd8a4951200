// PosixCommandRunner: runs plan commands on this machine (posix_spawnp on argv, no shell; stdin
// from /dev/null, stdout and stderr captured). I/O: part of swarmbox_faults, not of the pure
// fault model.
//
//   PosixCommandRunner local;
//   Status s = RunCommands(local, plan.apply);   // command_runner.hpp
#pragma once

#include <string>
#include <vector>

#include "swarmbox/faults/command_runner.hpp"

namespace swarmbox::faults {

class PosixCommandRunner : public CommandRunner {
 public:
  Result<CommandOutput> Run(const std::vector<std::string>& argv) override;
};

}  // namespace swarmbox::faults
