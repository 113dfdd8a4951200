// Running an experiment: every planned trial on a pool of hosts, into one folder, resumable.
//
//   auto spec = LoadExperiment("trials/experiments/radio.yaml");
//   auto plan = PlanExperiment(*spec);                       // every trial loaded and checked
//   std::vector<PoolHost> pool = {{"local", 2, &local_api, check, images}};
//   ExperimentOptions o;  o.out_dir = "runs/radio";  o.run_id = runner::NewRunId();
//   auto summary = RunExperiment(*plan, pool, o);
//
// Per attempt (TrialExecutor): a fresh staging folder, runner::RunTrialSpec with run id = the
// experiment's run id, trial id = name = the planned id (so parallel trials never collide and
// `swarmbox gc --run <run id>` finds all of an experiment on a host), host = the host's name.
// When the trial ends with outcome `error` and the host no longer answers, the attempt is the
// host's failure: its folder goes to .failed/, the trial back to the queue (scheduler.hpp).
// Otherwise trial_meta.json is added and the folder committed (trial_store.hpp). A trial that
// runs out of attempts is committed with outcome `error` and the reasons.
// By default a trial's containers and networks are removed in the background, one queue per host
// (background_removal.hpp): a slot starts its next trial once result.json is written; a failed
// removal is a problem of the summary.
// At the end: every background removal is waited for, every host still reachable is checked for
// anything left with the run's label (and cleaned), then results.csv and report.html are written
// from the trial folders.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/dsl/trial_spec.hpp"
#include "swarmbox/experiment/experiment_spec.hpp"
#include "swarmbox/experiment/scheduler.hpp"
#include "swarmbox/report/provenance.hpp"
#include "swarmbox/runner/runner.hpp"

namespace swarmbox::experiment {

struct ExperimentPlan {
  ExperimentSpec spec;
  std::vector<PlannedTrial> trials;
  std::map<std::string, dsl::TrialSpec> specs;  // by trial id
};

// Loads every trial (the base file with its overrides) through dsl::LoadTrial, so a bad level
// value stops the experiment before anything runs (kInvalidArgument naming the trial and the
// override).
Result<ExperimentPlan> PlanExperiment(const ExperimentSpec& spec);

struct PoolHost {
  std::string name;
  int slots = 1;
  docker::DockerApi* api = nullptr;
  std::function<Status()> check;  // does the engine answer now (with the host-level reason)
  runner::Images images;          // the images built on this host
  std::string faults_image;       // the fault sidecar image on this host ("" = none needed, or
                                  // let the runner build it per trial)
};

// The fault sidecar image on `api` when some trial of the plan impairs the mesh (built once per
// host instead of once per trial); "" when no trial needs it.
Result<std::string> EnsurePlanFaultsImage(const ExperimentPlan& plan, docker::DockerApi& api,
                                          const std::function<void(std::string_view)>& progress);

struct ExperimentOptions {
  std::string out_dir;
  std::string run_id;
  bool resume = false;
  int max_attempts = 3;
  const std::atomic<bool>* interrupted = nullptr;
  std::ostream* progress = nullptr;  // the live board; nullptr = quiet
  bool progress_tty = false;         // redraw in place (ANSI) rather than print blocks
  double progress_every_s = 2.0;
  // Remove each trial's containers and networks on a per-host thread while the slot launches its
  // next trial (false: inside the trial, before its result.json is written).
  bool remove_in_background = true;
  runner::RunOptions trial_options;  // the template for every trial (out_dir, run_id, trial_id,
                                     // host, images and interrupted are set per attempt)
};

struct ExperimentSummary {
  std::vector<TrialReport> reports;  // one per trial run in this session
  std::size_t total = 0;             // trials in the plan
  std::size_t done_before = 0;       // committed by an earlier run (--resume)
  std::size_t committed = 0;         // trials with a result.json now
  std::map<std::string, std::size_t> outcomes;  // over every committed trial
  std::vector<std::string> problems;  // cleanup and report issues, hosts that left
};

// experiment.json: {"name","file","base","factors":[...],"trials","run_ids":[...],
//   "provenance":{"swarmbox_version","swarmbox_commit","build_type","host_name","rtf_requested",
//                 "hosts":[{"name","images":[...],"docker_version","docker_api_version","kernel"}],
//                 "fault_mechanisms":[...],"rtf_achieved_min","rtf_achieved_max"}}
// (this build and machine, each host's images and engine, asked with GET /version now;
// rtf_requested null when the trials differ in it; the mechanisms and the rtf range from the
// `trials`' result.json provenance: RunExperiment writes the file before the trials with none and
// again at the end). Each trial's own is in its result.json and results.csv row
// (report/provenance.hpp).
std::string ExperimentJson(const ExperimentPlan& plan, const std::vector<std::string>& run_ids,
                           const std::vector<PoolHost>& pool,
                           const std::vector<report::Provenance>& trials = {});

// Whether `out_dir` can take this run: kInvalidArgument when it holds another experiment, or trials
// of this one and `resume` is false. Returns the run ids of earlier runs in the folder.
Result<std::vector<std::string>> CheckOutFolder(const ExperimentPlan& plan, const std::string& out_dir,
                                               bool resume);

// kInvalidArgument: the folder already holds this experiment's trials and resume is false, or it
// holds another experiment. kUnavailable: another run holds the folder. kIo: folder not writable.
Result<ExperimentSummary> RunExperiment(const ExperimentPlan& plan, const std::vector<PoolHost>& pool,
                                        const ExperimentOptions& options);

// results.csv, report.html and plots/*.svg (the page's box plots as files) of an experiment
// folder, and each trial's plots.html, from its trial folders (also `swarmbox report DIR`).
// Returns the number of trials found.
Result<std::size_t> WriteReports(const std::string& out_dir, std::vector<std::string>* problems);

}  // namespace swarmbox::experiment
