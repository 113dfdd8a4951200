// Booting the netem guest on the host: Debian's user-mode Linux kernel (package user-mode-linux,
// CONFIG_NET_SCH_NETEM=m) runs as an ordinary process with swarmbox-netem-guest as its init.
//
//   GuestBoot boot{.kernel = "/usr/bin/linux.uml", .init = SWARMBOX_NETEM_GUEST_BIN,
//                  .scratch_dir = dir, .scenarios = {"mesh"}};
//   auto run = BootGuest(boot, std::chrono::seconds(120));
//   if (!run) ...;                                // could not start, or no power-off in time
//   GuestConsole console = ParseGuestConsole(run->console);
//
// The guest's root is the host's file system through hostfs, mounted read-only (the guest reads the
// host's tc, ip, iptables, libraries and the UML module tree from it, and writes only to its own
// tmpfs); it has no network device but its own loopback and the veth pairs it creates, so no packet
// leaves it. UML's control files (umid) go to scratch_dir, and its memory file to $TMPDIR or /tmp
// (unlinked once mapped).
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::netem_guest {

inline constexpr const char* kUmlModulesDir = "/usr/lib/uml/modules";  // Debian's user-mode-linux

struct GuestBoot {
  std::string kernel;  // linux.uml
  std::string init;    // swarmbox-netem-guest, an absolute path on the host (= in the guest)
  std::string modules_dir = kUmlModulesDir;
  std::string scratch_dir;  // exists; UML's umid directory and the console file go here
  int mem_mb = 256;
  std::vector<std::string> scenarios;
};

// The kernel command line as argv: memory, hostfs root read-only, the init and its arguments after
// "--", the console on stdout, every other console and serial line off (no host pty), quiet.
std::vector<std::string> UmlArgv(const GuestBoot& boot);

struct GuestRun {
  int exit_code = 0;    // linux.uml's: 0 after the guest powered off
  std::string console;  // everything the guest printed (kernel lines and the records)
  double wall_s = 0.0;  // boot to power-off on the host [s]
};

// Runs the guest to its power-off. kTimeout (the console so far in the message) when it has not
// ended within `timeout`; it is then killed with its process group.
Result<GuestRun> BootGuest(const GuestBoot& boot, std::chrono::milliseconds timeout);

}  // namespace swarmbox::netem_guest
