// What a run writes (ARCHITECTURE.md "Per-trial output", contract): result.json and events.jsonl.
// Pure formatting and counting; the runner does the file I/O.
//
// result.json (one JSON object):
//   {"trial":"sar-search","outcome":"success","reason":"...","wall_s":312.5,"sim_s":300.2,
//    "seed":42,"host":"local","radio":{"model":"channel","profile":"wifi_5ghz_mesh"},"metrics":{...},"run_id":"...","trial_id":"...","source":"...",
//    "ending_line":"...","restarts":0,"components":[{"name":"physics","exit_code":0,...}],
//    "problems":[...],"provenance":{...}}
// "metrics" are results.csv's metric columns (report/trial_metrics.hpp, the one definition of
// each; computed by report::ReadTrialMetrics from the trial folder), every one present, null when
// the trial has no value for it, written as results.csv writes them (report::CsvNumber).
// "provenance": report/provenance.hpp.
// events.jsonl: one JSON object per line, in arrival order:
//   log events   {"wall_s":1.234,"component":"scout_1","t":12.34,"node":"scout_1","event":"...",...}
//   lifecycle    {"wall_s":0.5,"component":"orchestrator","event":"run","target":"physics",
//                 "outcome":"success"}
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/dsl/outcome.hpp"
#include "swarmbox/report/provenance.hpp"
#include "swarmbox/report/trial_metrics.hpp"

namespace swarmbox::runner {

struct ComponentReport {
  std::string name;
  std::optional<std::int64_t> exit_code;  // nullopt when never started or not inspected
  bool oom_killed = false;
  std::string log_file;                   // relative to the trial folder: logs/<name>.log
  std::uint64_t log_lines = 0;
};

// How long the trial took to start and to go, in wall seconds since the run began (result.json
// "timing"; `swarmbox-bench swarm` reports them): nullopt = did not happen.
struct TrialTiming {
  std::size_t containers = 0;          // of the (last) tree
  std::optional<double> created_s;     // the last container created
  std::optional<double> started_s;     // the last container started
  std::optional<double> joined_s;      // the physics server's event=joined (its start complete)
  std::optional<double> teardown_s;    // duration: the first Stop to the last removal
};

struct TrialResult {
  std::string trial;
  std::string trial_id;
  std::string run_id;
  dsl::Verdict verdict;
  double wall_s = 0;
  double sim_s = 0;
  std::uint64_t seed = 0;
  std::string host;
  // "radio": {"model": ..., "profile": ...} (profile null for netem); both "" = not written.
  std::string radio_model;
  std::string radio_profile;
  report::MetricValues metrics;  // by report::MetricNames()
  report::Provenance provenance;
  std::vector<ComponentReport> components;
  int restarts = 0;
  std::string ending_line;
  std::vector<std::string> problems;  // teardown/collection issues that did not change the outcome
  TrialTiming timing;
};

std::string ResultJson(const TrialResult& result);

// The achieved real-time factor: simulated seconds over wall seconds between the first and the last
// simulated time observed (pure; fed by the runner's watch loop).
class RtfMeter {
 public:
  void Observe(double wall_s, double sim_s);
  // nullopt until simulated time has moved on over some wall time.
  std::optional<double> Achieved() const;

 private:
  std::optional<std::pair<double, double>> first_;  // (wall, sim) when sim first moved past 0
  std::pair<double, double> last_{0, 0};
};

// One events.jsonl line (no trailing newline) for a logfmt line that has an `event` field;
// nullopt for other lines.
std::optional<std::string> LogEventJson(double wall_s, std::string_view component,
                                        const LogfmtFields& fields);
std::string LifecycleEventJson(double wall_s, std::string_view event, std::string_view target,
                               const dsl::Verdict& verdict);

// The CLI exit code of a verdict (ARCHITECTURE.md "CLI"): 0 success, 1 timeout/failure,
// 3 error (infrastructure).
int ExitCodeFor(const dsl::Verdict& verdict);

}  // namespace swarmbox::runner
