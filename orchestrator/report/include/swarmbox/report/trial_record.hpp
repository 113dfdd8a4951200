// A trial of an experiment as the results see it: one results.csv row. Read back from the trial's
// folder (I/O in ReadTrialFolder; everything else pure).
//
// Files read in <experiment>/<trial>/:
//   trial_meta.json  written by `swarmbox experiment`: {"id","code","levels":[...],
//                    "factors":[...],"repetition","seed","attempts","hosts":[...]}
//   result.json      the runner's (outcome, reason, wall_s, sim_s, seed, host, provenance)
//   logs/*.log       logfmt events per component (the file stem is the component)
//   events.jsonl     orchestrator records (fault events for failover)
//   truth.csv        ground truth (min separation, the plots)
// and at the experiment level <experiment>/experiment.json: {"name","run_id","factors":[...]}.
// The metrics are computed from logs/, events.jsonl and truth.csv (ReadTrialMetrics, the same
// function the runner uses for result.json's "metrics"); a folder whose logs/ holds no log (pruned,
// as in docs/example-report) keeps the metrics its result.json stored. WriteTrialPlots writes the
// folder's plots.html from the same logs and truth.csv.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/report/provenance.hpp"
#include "swarmbox/report/trial_metrics.hpp"
#include "swarmbox/report/trial_plots.hpp"
#include "swarmbox/report/trial_series.hpp"

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
  bool has_plots = false;         // plots.html exists
};

// Calls `on_row` for every well-formed row of a truth.csv (columns t_s, drone, x_m, y_m, z_m by
// the header; vx_m_s, vy_m_s, vz_m_s and qw..qz, p_rad_s..r_rad_s when it has them). Rows that do
// not parse are skipped. false
// when the file cannot be read or its header lacks a column.
bool ReadTruthCsv(const std::string& path, const std::function<void(const TruthRow&)>& on_row);

// The metrics of a trial folder from its logs/*.log, events.jsonl and truth.csv (TrialMetrics fed
// in that order, logs sorted by name). nullopt when logs/ holds no .log file.
std::optional<MetricValues> ReadTrialMetrics(const std::string& dir);

// Reads one trial folder (kNotFound when it has no result.json).
Result<TrialRecord> ReadTrialFolder(const std::string& dir);

// Every trial folder (a sub-folder with result.json) of an experiment folder, sorted by trial id;
// unreadable folders are reported in `problems`.
// One trial folder's series over time (trial_series.hpp) from its logs/*.log (sorted by name) and
// truth.csv. `found` (optional) says whether there was any log line or truth row to read.
TrialSeries ReadTrialSeries(const std::string& dir, bool* found = nullptr);

// Writes DIR/plots.html (trial_plots.hpp) from the folder's logs and truth.csv. false (and
// nothing written, an older plots.html kept) when the folder has neither, as a folder whose logs
// were pruned (docs/example-report); an I/O error otherwise.
Result<bool> WriteTrialPlots(const std::string& dir, const TrialPlotsPage& page);

std::vector<TrialRecord> ReadExperimentFolder(const std::string& dir,
                                              std::vector<std::string>* problems);

// The report's title: experiment.json's "name", else the folder's name.
std::string ExperimentTitle(const std::string& dir);

// Factor names of an experiment folder: experiment.json, else the first trial's meta.
std::vector<std::string> FactorNames(const std::string& dir, const std::vector<TrialRecord>& records);

}  // namespace swarmbox::report
