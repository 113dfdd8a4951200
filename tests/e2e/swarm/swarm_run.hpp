// RunSwarmTrial: trials/swarm_100.yaml at a given size, run for real through the trial runner
// (runner::RunTrialSpec, the path of `swarmbox run`) on the local Docker engine, with the agents'
// and the physics server's cgroups sampled every second, for swarmbox-bench swarm and SwarmE2e.
// The images are packed from this build tree's swarmbox-physics and swarmbox-agent (once per
// process). Whatever happens, nothing labelled with the run id stays on the engine.
//
//   auto api = ConnectDocker();
//   auto spec = LoadSwarmTrial(50, 30.0);       // 50 scouts + the lifter, 30 simulated s
//   SwarmRunConfig cfg;  cfg.out_dir = "/tmp/x";
//   auto run = RunSwarmTrial(**api, *spec, cfg);
//   FormatSwarmLine(run->figures);              // drones=51 rtf=... cpu_per_drone=... ...
#pragma once

#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "swarm_figures.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/dsl/trial_spec.hpp"
#include "swarmbox/runner/runner.hpp"

namespace swarmbox::swarm {

// The search area for `scouts`: sqrt(N) x 60 m a side (about 3,600 m^2 per scout), at least 150 m
// (open_field's victims lie within 84 x 110 m) [m].
double SearchSideM(int scouts);

// trials/swarm_100.yaml with `scouts` scouts on SearchSideM, the simulated timeout `sim_s` (0 =
// the file's), then `sets` (--set overrides).
Result<dsl::TrialSpec> LoadSwarmTrial(int scouts, double sim_s, const std::vector<std::string>& sets = {});

Result<std::unique_ptr<docker::DockerApi>> ConnectDocker();

struct SwarmRunConfig {
  std::string out_dir;               // the trial folder goes under it
  std::ostream* progress = nullptr;  // the runner's progress lines; nullptr = quiet
};

struct SwarmRun {
  runner::RunOutcome outcome;
  SwarmFigures figures;
  std::vector<std::string> events;  // events.jsonl's lines
  int cgroups_read = 0;             // containers whose cgroup counters were read at least once
};

Result<SwarmRun> RunSwarmTrial(docker::DockerApi& api, const dsl::TrialSpec& spec, const SwarmRunConfig& config);

}  // namespace swarmbox::swarm
