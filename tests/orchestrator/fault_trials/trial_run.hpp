// RunFaultTrial: one trial description run for real through the trial runner (runner::RunTrial,
// the same path as `swarmbox run`) on the local Docker engine, for the fault-trial tests and the
// `faults` benchmark. The images are packed from this build tree's swarmbox-physics,
// swarmbox-agent and swarmbox-netemd (once per process). Whatever happens, nothing labelled with
// the run id stays on the engine (the runner removes what it made; a second sweep by label runs
// after it, also when it failed).
//
//   auto api = ConnectDocker();                       // kUnavailable: no engine
//   TrialRunConfig cfg;  cfg.out_dir = "/tmp/x";  cfg.extra_agent_flags = {{"--propose-every-ms", "500"}};
//   auto run = RunFaultTrial(**api, spec, cfg);
//   run->outcome.result.verdict.outcome;  run->events;  run->outcome.trial_dir
//
// extra_agent_flags: appended to every agent's command line after the runner's own, unless the
// runner already passes that flag (the agent refuses a repeated flag): the agent's diagnostic
// flags that have no trial key (--propose-every-ms, a Raft demo proposer), or a flag the runner
// does not pass yet.
#pragma once

#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/dsl/trial_spec.hpp"
#include "swarmbox/runner/runner.hpp"
#include "trial_events.hpp"

namespace swarmbox::fault_trials {

struct TrialRunConfig {
  std::string out_dir;                        // the trial folder goes under it
  std::vector<std::pair<std::string, std::string>> extra_agent_flags;  // {flag, value}
  std::ostream* progress = nullptr;           // the runner's progress lines; nullptr = quiet
};

struct TrialRun {
  runner::RunOutcome outcome;
  std::vector<TrialEvent> events;  // its events.jsonl
};

Result<std::unique_ptr<docker::DockerApi>> ConnectDocker();

// The trial file trials/faults/<name> of this source tree, loaded strictly (with --set style
// overrides "key=value").
Result<dsl::TrialSpec> LoadFaultTrial(const std::string& name,
                                      const std::vector<std::string>& sets = {});

// Errors: the images cannot be built, the output folder cannot be made, the engine does not
// answer (nothing ran). Every later problem is the trial's outcome.
Result<TrialRun> RunFaultTrial(docker::DockerApi& api, const dsl::TrialSpec& spec,
                               const TrialRunConfig& config);

// Whether this build's swarmbox-agent has a flag (its --help mentions it).
bool AgentHasFlag(const std::string& flag);

}  // namespace swarmbox::fault_trials
