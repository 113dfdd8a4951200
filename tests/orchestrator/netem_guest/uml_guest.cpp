#include "uml_guest.hpp"

#include <unistd.h>

#include "support/child_process.hpp"
#include "support/files.hpp"

namespace swarmbox::netem_guest {

std::vector<std::string> UmlArgv(const GuestBoot& boot) {
  std::vector<std::string> argv = {
      boot.kernel,
      "mem=" + std::to_string(boot.mem_mb) + "M",
      "rootfstype=hostfs",
      "rootflags=/",
      "ro",
      "init=" + boot.init,
      "umid=netem-guest-" + std::to_string(getpid()),
      "uml_dir=" + boot.scratch_dir,
      // con0 (the init's stdin/stdout) reads nothing and writes to linux.uml's stdout; the other
      // consoles and the serial lines would each open a host pty.
      "con0=null,fd:1",
      "con=null",
      "ssl=null",
      "quiet",
      "loglevel=1",
      "--",
      "--modules",
      boot.modules_dir,
  };
  for (const std::string& s : boot.scenarios) {
    argv.push_back("--scenario");
    argv.push_back(s);
  }
  return argv;
}

Result<GuestRun> BootGuest(const GuestBoot& boot, std::chrono::milliseconds timeout) {
  const std::string console_path = boot.scratch_dir + "/console.txt";
  const auto start = std::chrono::steady_clock::now();
  auto child = testing::ChildProcess::Spawn(UmlArgv(boot), console_path, console_path);
  if (!child) return child.error();
  const std::optional<int> code = child->Wait(timeout);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!code) {
    child->Stop(std::chrono::seconds(2));
    return Error(ErrorCode::kTimeout,
                 "the guest did not power off within " + std::to_string(timeout.count()) +
                     " ms; its console:\n" + testing::ReadWholeFile(console_path),
                 boot.kernel);
  }
  return GuestRun{*code, testing::ReadWholeFile(console_path), wall_s};
}

}  // namespace swarmbox::netem_guest
