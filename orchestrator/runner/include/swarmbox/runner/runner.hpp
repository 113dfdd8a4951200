// The trial runner: `swarmbox run TRIAL.yaml`.
//
//   SteadyClock clock;
//   RunOptions opts;  opts.out_dir = "runs"; opts.images = {...}; opts.progress = &std::cerr;
//   auto run = RunTrialSpec(spec, api, clock, opts);
//   if (!run) return 3;                       // nothing was started (cannot write the folder...)
//   return ExitCodeFor(run->result.verdict);  // 0 success, 1 timeout/failure, 3 error
//
// One run: make <out>/<trial>-<run id>/ (trial.yaml, logs/), pick subnets (retrying on a
// conflict), Build and Run the tree in priority order, then watch: every container's log is
// streamed to logs/<component>.log as it comes, end conditions are matched, the simulated clock
// (physics `t=`) and the wall-clock guard are checked, progress is printed. The first end (or
// Ctrl-C) fires Shutdown; faults (TrialInfo::mesh/faults) are applied by a FaultInjector: the
// mesh block before the agents start, the schedule while watching, everything undone before Stop;
// with the simulated radio (TrialInfo::planned_faults) the physics server schedules process
// faults and the injector carries out the container action it reports.
// Then Stop (reverse priority) stops, collects logs and artifacts
// (truth.csv) and removes containers and networks. Written at the end: result.json, events.jsonl
// (written as events arrive), trajectories.png (from truth.csv and the world).
// A Restart raised during the run (a broken log stream) rebuilds the trial, at most
// `max_restarts` times.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/dsl/trial.hpp"
#include "swarmbox/dsl/trial_spec.hpp"
#include "swarmbox/runner/clock.hpp"
#include "swarmbox/runner/plan.hpp"
#include "swarmbox/runner/results.hpp"
#include "swarmbox/runner/subnets.hpp"

namespace swarmbox::runner {

struct RunOptions {
  std::string out_dir = "runs";
  std::string run_id;    // "" = NewRunId()
  std::string trial_id;  // "" = the trial's name
  Images images;         // for RunTrialSpec
  // The fault sidecar image for trials that impair the mesh; "" = RunTrialSpec builds it from
  // swarmbox-netemd (netemd_bin, or FindNetemd's search).
  std::string faults_image;
  std::string host = "local";
  const std::atomic<bool>* interrupted = nullptr;  // set by Ctrl-C or SIGTERM
  // The trial's reason once `interrupted` is set, e.g. "interrupted (SIGTERM)"; empty: the
  // reason is "interrupted (Ctrl-C)".
  std::function<std::string()> interrupt_reason;
  std::ostream* progress = nullptr;                // status lines; nullptr = quiet
  std::chrono::milliseconds poll{200};             // how long the watch loop waits for lines
  double progress_every_s = 2.0;
  int max_restarts = 1;
  int subnet_attempts = 5;
  // Containers created (ahead) and started at once (EngineOptions::max_parallel); 0 =
  // $SWARMBOX_PARALLEL when set (1 = one at a time, nothing created ahead), else 32.
  int max_parallel = 0;
  // swarmbox-netemd for the fault sidecar image, when faults_image is "" and the trial impairs
  // the mesh ("" = FindNetemd's search, fault_image.hpp).
  std::string netemd_bin;
  // The host swarmbox-agent: RunTrialSpec packs the agent image of a drone with a library brain
  // from it when `images.drone_agents` lacks that drone (user_images.hpp; brains' and components'
  // images missing from `images` are made the same way).
  std::string agent_binary;
  // swarmbox run --view: publish the physics server's live view on this host (local engine only).
  std::optional<ViewBinding> view;
};

struct RunOutcome {
  TrialResult result;
  std::string trial_dir;
};

// What the runner needs to know about a trial besides its tree.
struct TrialInfo {
  std::string name;
  std::uint64_t seed = 0;
  std::optional<double> rtf;  // physics.rtf as asked (provenance); nullopt = not known
  std::string resolved_yaml;  // written as trial.yaml
  std::string world_file;     // host path of the world (for trajectories.png); "" = none
  // Faults (fault_injector.hpp): carried out when either is non-empty. Drone names in trial
  // order; each drone is a Plugin of that id in the tree, and with network faults its sidecar
  // SidecarId(drone) is a Plugin on the "mesh" network and the tree has the Step kFaultsStepId.
  std::vector<std::string> drones;
  faults::MeshImpairment mesh;
  std::vector<faults::Fault> faults;
  // The sim bus's middleware: sensor and environment faults are sent to the tree's Plugin
  // kPhysicsId with PhysicsCommandArgv (plan.hpp).
  dsl::Middleware middleware = dsl::Middleware::kCycloneDds;
  // The radio model ("channel", "netem"; "" = not said, e.g. a C++ DSL tree) and the channel's
  // profile, for result.json's "radio". netem with rtf != 1 is warned about (events.jsonl).
  std::string radio_model;
  std::string radio_profile;
  // Faults the physics server carries out at simulated times (the radio plan's, radio.model
  // channel): the runner does the container action when the server reports `event=drone_out` /
  // `event=drone_back` and records `event=radio_fault` (fault_injector.hpp). Not in `faults`.
  std::vector<faults::Fault> planned_faults;
  // Files written into the trial folder before the tree is planned (name -> content), e.g. the
  // radio plan (plan.hpp kRadioPlanFile) the planner copies into the physics container.
  std::map<std::string, std::string> files;
};

// The warning for a netem trial at an rtf other than 1 (its radio runs on the wall clock);
// nullopt otherwise. RunTrial writes it to events.jsonl ({"event":"warning",...}); `swarmbox run`
// prints it too.
std::optional<std::string> RadioRtfWarning(std::string_view radio_model, std::optional<double> rtf);

// Builds the tree for a pair of subnets (called again with others after a subnet conflict).
using Planner = std::function<Result<std::unique_ptr<dsl::Trial>>(const std::string& run_id,
                                                                   const TrialSubnets& subnets)>;

// Runs any tree (the C++ DSL, tests). The Result is an error only when nothing could be started
// (the output folder cannot be made, the engine does not answer); every later problem is the
// outcome in the result.
Result<RunOutcome> RunTrial(const TrialInfo& info, const Planner& planner, docker::DockerApi& api,
                            Clock& clock, const RunOptions& options);

// Runs a trial description: PlanTrial + RunTrial.
Result<RunOutcome> RunTrialSpec(const dsl::TrialSpec& spec, docker::DockerApi& api, Clock& clock,
                                const RunOptions& options);

}  // namespace swarmbox::runner
