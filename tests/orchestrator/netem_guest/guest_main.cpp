// swarmbox-netem-guest: the init (PID 1) of the user-mode Linux guest in which the kernel netem
// path is measured (tests/orchestrator/netem_guest/README.md).
//
//   linux.uml ... init=/path/to/swarmbox-netem-guest -- --modules /usr/lib/uml/modules
//       --scenario mesh [--scenario rate ...]       (one command line: uml_guest.hpp builds it)
//
// It mounts the guest's own /proc, /sys, /tmp and /run (the root is the host's file system, seen
// read-only through hostfs), loads veth, sch_netem, htb, u32 and the iptables filter table from the UML
// kernel's module tree (and points `iptables` at its legacy build, see kGuestBinDir), runs each scenario
// (guest_scenarios.hpp) on fresh network namespaces, prints its records on the console (guest_console.hpp)
// and powers the guest off. It refuses to run anywhere but as PID 1 of a user-mode Linux kernel (it mounts
// over /tmp and /run and powers off).
#include <sys/mman.h>
#include <sys/mount.h>
#include <sys/reboot.h>
#include <sys/stat.h>
#include <sys/utsname.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "guest_console.hpp"
#include "guest_lab.hpp"
#include "guest_scenarios.hpp"
#include "kernel_modules.hpp"
#include "support/files.hpp"

namespace swarmbox::netem_guest {
namespace {

// The modules the scenarios need: the veth pair, netem and the per-destination tree (htb + u32),
// and the iptables filter table for the partitions.
const std::vector<std::string> kModules = {"veth", "sch_netem", "sch_htb", "cls_u32", "iptable_filter"};

// Debian's UML kernel has legacy iptables (ip_tables, iptable_filter) but no nf_tables for IPv4
// (CONFIG_NF_TABLES_IPV4 is not set), while the host's `iptables` is usually iptables-nft. Inside
// the guest, `iptables` is therefore the legacy build of the same xtables (a symlink first in PATH,
// on the guest's own tmpfs): the plans' argv are unchanged and the rules (INPUT chains with DROP)
// mean the same under both backends.
constexpr const char* kGuestBinDir = "/run/swarmbox-guest-bin";
constexpr const char* kLegacyIptables = "/usr/sbin/xtables-legacy-multi";

double UptimeS() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) / 1e9;
}

class ConsoleReporter : public Reporter {
 public:
  void Record(std::string_view event, const Fields& fields) override {
    const std::string line = GuestLine(UptimeS(), event, fields) + "\n";
    std::fwrite(line.data(), 1, line.size(), stdout);
    std::fflush(stdout);
    if (event == kEventError) ++errors_;
  }
  int errors() const { return errors_; }

 private:
  int errors_ = 0;
};

Status MountFs(const char* type, const char* target, const char* options) {
  if (mount(type, target, type, MS_NOSUID | MS_NODEV, options) != 0) {
    return Error(ErrorCode::kIo,
                 std::string("mount ") + type + " on " + target + ": " + std::strerror(errno));
  }
  return Ok{};
}

Status PrepareGuest(const std::string& modules_root, ConsoleReporter& report) {
  SWARMBOX_TRY(MountFs("sysfs", "/sys", nullptr));
  SWARMBOX_TRY(MountFs("tmpfs", "/tmp", "mode=1777"));
  SWARMBOX_TRY(MountFs("tmpfs", "/run", "mode=0755"));
  if (mkdir(kGuestBinDir, 0755) != 0 ||
      symlink(kLegacyIptables, (std::string(kGuestBinDir) + "/iptables").c_str()) != 0) {
    return Error(ErrorCode::kIo, std::string("the guest's iptables link: ") + std::strerror(errno),
                 kGuestBinDir);
  }
  // The kernel starts init with HOME and TERM only; tc, ip and iptables live in /usr/sbin.
  setenv("PATH", (std::string(kGuestBinDir) + ":/usr/sbin:/usr/bin:/sbin:/bin").c_str(), 1);
  utsname uts{};
  uname(&uts);
  const std::string dir = modules_root + "/" + uts.release;
  const std::string dep = testing::ReadWholeFile(dir + "/modules.dep");
  if (dep.empty())
    return Error(ErrorCode::kNotFound, "no modules.dep for kernel " + std::string(uts.release), dir);
  auto order = ModuleLoadOrder(dep, kModules);
  if (!order) return order.error().Context(dir);
  SWARMBOX_TRY(LoadModules(dir, *order));
  report.Record(kEventReady, {{"kernel", uts.release}, {"modules", std::to_string(order->size())}});
  return Ok{};
}

[[noreturn]] void PowerOff() {
  sync();
  reboot(RB_POWER_OFF);
  std::_Exit(1);  // reboot() does not return as PID 1 of a kernel
}

bool RunningInUml() {
  // /proc as seen before mounting is the host's (through hostfs); the guest's own says so.
  if (mount("proc", "/proc", "proc", MS_NOSUID | MS_NODEV | MS_NOEXEC, nullptr) != 0) return false;
  return testing::ReadWholeFile("/proc/cpuinfo").find("User Mode Linux") != std::string::npos;
}

int Main(int argc, char** argv) {
  if (getpid() != 1 || !RunningInUml()) {
    std::fprintf(stderr,
                 "swarmbox-netem-guest: this is the init of the netem guest; it runs only as PID 1 of a "
                 "user-mode Linux "
                 "kernel (tests/orchestrator/netem_guest/README.md)\n");
    return 2;
  }
  // Every page of this program and its libraries in memory now: a page fault during a probe would
  // be a read through hostfs, which blocks the whole (single-threaded) guest kernel.
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    std::fprintf(stderr, "swarmbox-netem-guest: mlockall: %s\n", std::strerror(errno));
  }
  ConsoleReporter report;
  std::string modules_root = "/usr/lib/uml/modules";
  std::vector<std::string> names;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--modules" && i + 1 < argc) {
      modules_root = argv[++i];
    } else if (arg == "--scenario" && i + 1 < argc) {
      names.emplace_back(argv[++i]);
    } else if (arg.find('=') != std::string::npos) {
      continue;  // what UML appends to init's arguments after "--" (root=98:0 console=tty0)
    } else {
      report.Record(kEventError, {{"scenario", "guest"}, {"message", "unknown argument " + arg}});
    }
  }
  if (Status prepared = PrepareGuest(modules_root, report); !prepared) {
    report.Record(kEventError, {{"scenario", "guest"}, {"message", prepared.error().ToString()}});
  } else {
    faults::PosixCommandRunner posix;
    for (const std::string& name : names) {
      const Scenario* scenario = FindScenario(name);
      if (scenario == nullptr) {
        report.Record(kEventError, {{"scenario", name}, {"message", "no such scenario"}});
        continue;
      }
      const double start = UptimeS();
      GuestLab lab(posix, report, name);
      Status s = lab.Create();
      if (s) s = scenario->run(lab);
      if (!s) report.Record(kEventError, {{"scenario", name}, {"message", s.error().ToString()}});
      char took[32];
      std::snprintf(took, sizeof took, "%.2f", UptimeS() - start);
      report.Record("scenario_end", {{"scenario", name}, {"took_s", took}});
    }
  }
  report.Record(kEventDone,
                {{"scenarios", std::to_string(names.size())}, {"errors", std::to_string(report.errors())}});
  PowerOff();
}

}  // namespace
}  // namespace swarmbox::netem_guest

int main(int argc, char** argv) {
  try {
    return swarmbox::netem_guest::Main(argc, argv);
  } catch (const std::exception& e) {
    const std::string line = swarmbox::netem_guest::GuestLine(0.0, swarmbox::netem_guest::kEventError,
                                                              {{"scenario", "guest"}, {"message", e.what()}});
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
    if (getpid() == 1) swarmbox::netem_guest::PowerOff();
    return 1;
  }
}
