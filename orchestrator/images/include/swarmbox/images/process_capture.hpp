// Running a helper program (argv array, no shell) and capturing its output: the one place the
// image packer starts processes (the ELF loader's --list mode).
//
//   auto r = RunCapture({"/lib64/ld-linux-x86-64.so.2", "--list", "/usr/sbin/tc"});
//   if (r && r->exit_code == 0) Use(r->out);
//
// posix_spawn with an argv array (argv[0] without '/' is searched in PATH), the caller's environment, stdin from /dev/null. Errors: kNotFound
// when the program cannot be started, kIo for pipe failures; a non-zero exit is not an error
// (it is in exit_code; a signal death gives 128 + signal). Thread-safe.
#pragma once

#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::images {

struct CapturedRun {
  int exit_code = 0;
  std::string out;
  std::string err;
};

Result<CapturedRun> RunCapture(const std::vector<std::string>& argv);

}  // namespace swarmbox::images
