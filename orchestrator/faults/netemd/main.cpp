// swarmbox-netemd: the userspace delayer for hosts whose kernel has no sch_netem. Usage and flags:
// see swarmbox/faults/netemd_args.hpp. Thin: parsing in netemd_args, scheduling in DelayScheduler,
// the queue in NfqueueDelayer, processes in process_control.
#include <cstdio>
#include <string>
#include <vector>

#include "nfqueue_delayer.hpp"
#include "process_control.hpp"
#include "swarmbox/common/version.hpp"
#include "swarmbox/faults/netemd_args.hpp"

namespace {

constexpr const char* kUsage =
    "usage: swarmbox-netemd run --queue N [--delay-us U] [--jitter-us U] [--distribution "
    "uniform|normal|pareto|paretonormal]\n"
    "                           [--correlation F] [--reorder F] [--reorder-correlation F] [--reorder-gap N]\n"
    "                           [--seed S] [--queue-maxlen N] [--pidfile /run/x.pid] [--daemonize]\n"
    "                           [--ge-p F --ge-r F --ge-loss-bad F --ge-loss-good F] [--corrupt F]\n"
    "       swarmbox-netemd stop --pidfile /run/x.pid\n"
    "       swarmbox-netemd sleep\n"
    "       swarmbox-netemd --version\n";

int Serve(const swarmbox::faults::NetemdArgs& args, const std::function<void()>& ready) {
  auto delayer = swarmbox::faults::NfqueueDelayer::Open(args);
  if (!delayer) {
    std::fprintf(stderr, "swarmbox-netemd: %s\n", delayer.error().ToString().c_str());
    return 1;
  }
  ready();
  const auto status = (*delayer)->Run();
  const auto& s = (*delayer)->stats();
  std::fprintf(stderr,
               "swarmbox-netemd: queue=%u packets=%llu reordered=%llu dropped=%llu corrupted=%llu mean_hold_ms=%.3f overruns=%llu "
               "verdict_errors=%llu\n",
               args.queue, static_cast<unsigned long long>(s.packets), static_cast<unsigned long long>(s.reordered),
               static_cast<unsigned long long>(s.dropped), static_cast<unsigned long long>(s.corrupted),
               s.mean_hold_ms, static_cast<unsigned long long>(s.receive_overruns),
               static_cast<unsigned long long>(s.verdict_errors));
  if (!status) {
    std::fprintf(stderr, "swarmbox-netemd: %s\n", status.error().ToString().c_str());
    return 1;
  }
  return 0;
}

// "stop --pidfile P": SIGTERM to the daemon the pidfile names, waiting up to kStopTimeoutMs.
int StopCommand(const std::vector<std::string>& words) {
  constexpr int kStopTimeoutMs = 5000;
  if (words.size() != 2 || words[0] != "--pidfile") {
    std::fputs(kUsage, stderr);
    return 2;
  }
  auto s = swarmbox::faults::StopByPidfile(words[1], kStopTimeoutMs);
  if (!s) {
    std::fprintf(stderr, "swarmbox-netemd: %s\n", s.error().ToString().c_str());
    return 1;
  }
  return 0;
}

// "run ...": serves the queue in the foreground, or as a daemon once the queue is bound.
int RunCommand(const std::vector<std::string>& words) {
  auto args = swarmbox::faults::ParseNetemdRunArgs(words);
  if (!args) {
    std::fprintf(stderr, "swarmbox-netemd: %s\n%s", args.error().message().c_str(), kUsage);
    return 2;
  }
  if (args->daemonize) {
    return swarmbox::faults::Daemonize(
        args->pidfile, [&](const std::function<void()>& ready) { return Serve(*args, ready); });
  }
  return Serve(*args, [] {});
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> words(argv + 1, argv + argc);
  if (words.empty() || words[0] == "--help" || words[0] == "-h") {
    std::fputs(kUsage, words.empty() ? stderr : stdout);
    return words.empty() ? 2 : 0;
  }
  if (words[0] == "--version") {
    std::printf("%s\n", swarmbox::VersionLine("swarmbox-netemd").c_str());
    return 0;
  }
  const std::string command = words[0];
  words.erase(words.begin());
  if (command == "sleep") return swarmbox::faults::SleepAsInit();
  if (command == "stop") return StopCommand(words);
  if (command != "run") {
    std::fprintf(stderr, "swarmbox-netemd: unknown command '%s'\n%s", command.c_str(), kUsage);
    return 2;
  }
  return RunCommand(words);
}
