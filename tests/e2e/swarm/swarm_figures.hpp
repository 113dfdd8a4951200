// The figures of one swarm trial (swarmbox-bench swarm, SwarmE2e): what a finished trial folder
// and samples of the containers' cgroups say about scale. Pure: the caller reads the files.
//
//   SwarmFigures f = ComputeSwarmFigures(result, events_lines, samples, drones);
//   std::puts(FormatSwarmLine(f, 100).c_str());
//   // drones=100 agents=101 rtf=1.3 cpu_per_drone=0.021 mem_per_agent_mib=11.2 mission_complete=1 ...
//
// Definitions (BENCHMARKS.md "swarm"):
//   drones              the size asked: scouts (drones.scout.count); agents = every drone, the lifter
//                       too, and the per-drone figures are per agent
//   rtf                 the runner's achieved real-time factor (result.json provenance.rtf_achieved)
//   cpu_per_drone       agent CPU per drone per simulated second [cores at real time]: the sum of
//                       the agents' cgroup CPU time over (drones x simulated seconds); 0.035 means
//                       a drone needs 3.5 % of a core to fly at rtf 1. physics_cpu is the physics
//                       server's, on the same scale (cores at real time, the whole world). It
//                       counts each container's whole life: its start (loading, discovery, the
//                       wait for the last drone to join, which grows with the fleet) and its exit.
//   flying_cpu_per_drone the same between the first sample after simulated time moves (start_s)
//                       and the last before the first stop, over the simulated time between them
//                       (the largest t of events.jsonl's lines by then): what a drone costs per
//                       simulated second in flight, the figure that shows whether per-drone work
//                       grows with the fleet ("-" without two such samples)
//   start_cpu_per_agent_s the mean agent's CPU time [s] before simulated time moved (that sample)
//   mem_per_agent_mib   the mean over agents of each agent container's peak memory (cgroup v1
//                       memory.max_usage_in_bytes: RSS and page cache) [MiB]; mem_agent_max_mib the
//                       largest; mem_total_mib the largest sum over all containers at one sample
//   mission_complete    1 when the trial ended on event=mission_complete; mission_s its simulated time
//   msgs_per_drone_s    radio frames the drones sent per drone per simulated second (the physics
//                       server's last event=channel `sent`, over drones and its t)
//   lost                drones lost to the infrastructure: the lockstep's lost drones (last
//                       event=clock lost=), or agents that exited non-zero or were OOM-killed,
//                       whichever is more
//   joined              agents that logged event=ready
//   start_s             wall time from the run's start to simulated time moving (the first line
//                       with t > 0: every drone has joined the lockstep)
//   exit_s              wall time from the first stop to the run's end (stop, collect, remove)
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace swarmbox::swarm {

// One container's cgroup counters at one sample.
struct CgroupSample {
  double cpu_s = 0;          // cumulative CPU time [s] (cpuacct.usage)
  double mem_mib = 0;        // current usage [MiB] (memory.usage_in_bytes)
  double mem_peak_mib = 0;   // peak usage so far [MiB] (memory.max_usage_in_bytes)
};

// One sample of every container, taken `wall_s` after the run's start (the clock of events.jsonl's
// wall_s, within the sampler's period).
struct CgroupSnapshot {
  double wall_s = 0;
  std::map<std::string, CgroupSample> containers;  // by component name ("physics", "scout_1", ...)
};

// Samples over the trial, in time order.
using CgroupSamples = std::vector<CgroupSnapshot>;

// What result.json says that the figures need.
struct TrialSummary {
  std::string outcome;       // "success", "timeout", ...
  std::string ending_line;   // the line that ended it ("" = timeout or an error)
  double wall_s = 0;
  double sim_s = 0;
  std::optional<double> rtf_achieved;
  std::optional<double> mission_time_s;
  int failed_agents = 0;     // agents with a non-zero exit code or OOM-killed
};

struct SwarmFigures {
  int drones = 0;  // agents: every drone of the trial
  std::optional<double> rtf;
  double cpu_per_drone = 0;
  std::optional<double> flying_cpu_per_drone;
  std::optional<double> start_cpu_per_agent_s;
  double physics_cpu = 0;
  double mem_per_agent_mib = 0;
  double mem_agent_max_mib = 0;
  double mem_total_mib = 0;
  bool mission_complete = false;
  std::optional<double> mission_s;
  double msgs_per_drone_s = 0;
  int lost = 0;
  int joined = 0;
  std::optional<double> start_s;
  double exit_s = 0;
  double sim_s = 0;
  double wall_s = 0;
  std::string outcome;
};

// `events` are the lines of events.jsonl; `drones` the trial's drone names.
SwarmFigures ComputeSwarmFigures(const TrialSummary& result, const std::vector<std::string>& events,
                                 const CgroupSamples& samples, const std::vector<std::string>& drones);

// result.json's text -> the summary (fields missing are left at their defaults).
TrialSummary ParseResultJson(std::string_view json);

// `drones=<scouts> agents=... rtf=... ...` (the bench's line; "-" for a figure that is not known).
std::string FormatSwarmLine(const SwarmFigures& f, int scouts);

}  // namespace swarmbox::swarm
