// swarmbox-bench swarm: the full SAR agent in containers at several swarm sizes, one after the
// other, on the local Docker engine (BENCHMARKS.md "swarm").
//
//   swarmbox-bench swarm [--drones=10,50,100] [--sim-s 60] [--airframe=x500_depth] [--out DIR] [--keep=1] [--quick]
//
// For each size N: trials/swarm_100.yaml with N scouts (drones.scout.count, plus the lifter: N + 1
// agents) on a search area of
// sqrt(N) x 60 m a side (>= 150 m), rtf 0, --sim-s simulated seconds (or the mission's end, if
// sooner), through the trial runner; one logfmt line per size (swarm_figures.hpp defines each
// figure):
//   suite=swarm drones=100 agents=101 rtf=... cpu_per_drone=... mem_per_agent_mib=... mission_complete=0|1
//   mission_s=... msgs_per_drone_s=... lost=0 start_s=... exit_s=... (then joined, physics_cpu,
//   flying_cpu_per_drone, start_cpu_per_agent_s,
//   mem_agent_max_mib, mem_total_mib, sim_s, wall_s, outcome, load1: the host's 1-minute load
//   average before the trial, and the trial folder with --keep)
// --quick: 3 scouts (and the lifter) for 10 simulated s (a ctest smoke test, label e2e: it needs Docker).
// Exit status 1 when a trial fails to run, a drone is lost or never joins, or no cgroup counter
// could be read (the CPU and memory figures would be meaningless).
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bench.hpp"
#include "swarm_run.hpp"

namespace {

using namespace swarmbox;

std::vector<int> ParseSizes(const std::string& text) {
  std::vector<int> sizes;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!part.empty()) sizes.push_back(std::atoi(part.c_str()));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return sizes;
}

std::string Load1() {
  std::ifstream in("/proc/loadavg");
  std::string load;
  in >> load;
  return load.empty() ? "-" : load;
}

int RunSwarmBench(const bench::Args& args) {
  // --drones counts scouts: each trial also flies the lifter.
  const std::vector<int> sizes = ParseSizes(args.Get("drones", args.quick ? "3" : "10,50,100"));
  const double sim_s = args.GetDouble("sim-s", args.quick ? 10.0 : 60.0);
  const bool keep = args.options.count("keep") > 0;
  // --record=off runs the trials with `record: {enabled: false}`: the pair of runs gives what the
  // recording costs the physics server at each size (physics_cpu with and without).
  const std::string record = args.Get("record", "on");
  if (record != "on" && record != "off") {
    std::fprintf(stderr, "swarm bench: --record=%s: on or off\n", record.c_str());
    return 2;
  }
  std::vector<std::string> sets;
  if (record == "off") sets.push_back("record.enabled=false");
  // --airframe=x500_depth flies the scouts with the OAK-D Pro's stereo pair (issue #23): the pair
  // of runs gives what depth costs at each size.
  if (const std::string airframe = args.Get("airframe", ""); !airframe.empty()) {
    sets.push_back("drones.scout.airframe=" + airframe);
  }
  const std::string out =
      args.Get("out", (std::filesystem::temp_directory_path() / "swarmbox-bench-swarm").string());
  if (sizes.empty()) {
    std::fprintf(stderr, "swarm bench: --drones wants sizes like 10,50,100\n");
    return 2;
  }
  for (int n : sizes) {
    if (n < 1 || n > 199) {
      std::fprintf(stderr, "swarm bench: --drones %d: a size is 1..199 scouts (a trial has at most 200 drones)\n", n);
      return 2;
    }
  }
  auto api = swarm::ConnectDocker();
  if (!api) {
    std::fprintf(stderr, "swarm bench: %s\n", api.error().ToString().c_str());
    return 1;
  }
  int failures = 0;
  for (int n : sizes) {
    auto spec = swarm::LoadSwarmTrial(n, sim_s, sets);
    if (!spec) {
      std::fprintf(stderr, "swarm bench: %s\n", spec.error().ToString().c_str());
      return 1;
    }
    const std::string load = Load1();
    swarm::SwarmRunConfig cfg;
    cfg.out_dir = out;
    auto run = swarm::RunSwarmTrial(**api, *spec, cfg);
    if (!run) {
      std::fprintf(stderr, "swarm bench: %d drones: %s\n", n, run.error().ToString().c_str());
      ++failures;
      continue;
    }
    const swarm::SwarmFigures& f = run->figures;
    std::printf("suite=swarm %s load1=%s%s\n", swarm::FormatSwarmLine(f, n).c_str(), load.c_str(),
                keep ? (" dir=" + run->outcome.trial_dir).c_str() : "");
    std::fflush(stdout);
    if (run->cgroups_read == 0) {
      std::fprintf(stderr, "swarm bench: %d drones: no container's cgroup counters were readable under "
                           "/sys/fs/cgroup: the cpu and memory figures are not measured\n", n);
      ++failures;
    }
    if (f.lost > 0 || f.joined < f.drones || !f.start_s) {
      std::fprintf(stderr, "swarm bench: %d drones: %d lost, %d of %d joined, outcome %s (%s)\n", n, f.lost,
                   f.joined, f.drones, f.outcome.c_str(), run->outcome.trial_dir.c_str());
      ++failures;
      continue;  // the folder stays for a look
    }
    if (!keep) std::filesystem::remove_all(run->outcome.trial_dir);
  }
  return failures > 0 ? 1 : 0;
}

}  // namespace

SWARMBOX_BENCH_SUITE(swarm, "the SAR swarm in containers at several sizes: rtf, CPU and memory per drone (--drones=10,50,100 --sim-s=60 --record=on|off --airframe=x500_depth --keep --out=DIR)",
                     RunSwarmBench);
