// A trial of an experiment as the results see it: one results.csv row. Read back from the trial's
// folder (I/O in ReadTrialFolder; everything else pure).
//
// Files read in <experiment>/<trial>/:
//   trial_meta.json  written by `swarmbox experiment`: {"id","code","levels":[...],
//                    "factors":[...],"repetition","seed","attempts","hosts":[...]}
//   result.json      the runner's (outcome, reason, wall_s, sim_s, seed, host, provenance)
//   logs/*.log       logfmt events per component (the file stem is the component)
//   events.jsonl     orchestrator records (fault events for failover)
//   truth.csv        ground truth (min separation)
// and at the experiment level <experiment>/experiment.json: {"name","run_id","factors":[...]}.
// The metrics are computed from logs/, events.jsonl and truth.csv (ReadTrialMetrics, the same
// function the runner uses for result.json's "metrics"); a folder whose logs/ holds no log (pruned,
// as in docs/example-report) keeps the metrics its result.json stored.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/report/provenance.hpp"
#include "swarmbox/report/trial_metrics.hpp"

namespace swarmbox::report {

struct TrialMeta {
  std::string id;
  std::string code;
  std::vector<std::string> factors;  // names, in code order
  std::vector<std::string> levels;   // labels, one per factor
  int repetition = 1;
  std::uint64_t seed = 0;
  int attempts = 1;
  std::vector<std::string> hosts;  // the host of every attempt, in order
};

std::string TrialMetaJson(const TrialMeta& meta);
Result<TrialMeta> ParseTrialMetaJson(std::string_view text, std::string_view where);

struct TrialRecord {
  std::string folder;  // the folder's name inside the experiment folder
  TrialMeta meta;
  std::string host;
  std::string outcome;
  std::string reason;
  std::optional<double> wall_s;
  std::optional<double> sim_s;
  MetricValues metrics;
  Provenance provenance;  // result.json's (empty for folders written before it existed)
  bool has_trajectories = false;  // trajectories.png exists
};

// The metrics of a trial folder from its logs/*.log, events.jsonl and truth.csv (TrialMetrics fed
// in that order, logs sorted by name). nullopt when logs/ holds no .log file.
std::optional<MetricValues> ReadTrialMetrics(const std::string& dir);

// Reads one trial folder (kNotFound when it has no result.json).
Result<TrialRecord> ReadTrialFolder(const std::string& dir);

// Every trial folder (a sub-folder with result.json) of an experiment folder, sorted by trial id;
// unreadable folders are reported in `problems`.
std::vector<TrialRecord> ReadExperimentFolder(const std::string& dir,
                                              std::vector<std::string>* problems);

// The report's title: experiment.json's "name", else the folder's name.
std::string ExperimentTitle(const std::string& dir);

// Factor names of an experiment folder: experiment.json, else the first trial's meta.
std::vector<std::string> FactorNames(const std::string& dir, const std::vector<TrialRecord>& records);

}  // namespace swarmbox::report
