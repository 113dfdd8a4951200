// What a run writes (ARCHITECTURE.md "Per-trial output", contract): result.json and events.jsonl.
// Pure formatting and counting; the runner does the file I/O.
//
// result.json (one JSON object):
//   {"trial":"sar-search","outcome":"success","reason":"...","wall_s":312.5,"sim_s":300.2,
//    "seed":42,"host":"local","metrics":{...},"run_id":"...","trial_id":"...","source":"...",
//    "ending_line":"...","restarts":0,"components":[{"name":"physics","exit_code":0,...}],
//    "problems":[...]}
// events.jsonl: one JSON object per line, in arrival order:
//   log events   {"wall_s":1.234,"component":"scout_1","t":12.34,"node":"scout_1","event":"...",...}
//   lifecycle    {"wall_s":0.5,"component":"orchestrator","event":"run","target":"physics",
//                 "outcome":"success"}
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/dsl/outcome.hpp"

namespace swarmbox::runner {

struct ComponentReport {
  std::string name;
  std::optional<std::int64_t> exit_code;  // nullopt when never started or not inspected
  bool oom_killed = false;
  std::string log_file;                   // relative to the trial folder: logs/<name>.log
  std::uint64_t log_lines = 0;
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
  std::map<std::string, double> metrics;
  std::vector<ComponentReport> components;
  int restarts = 0;
  std::string ending_line;
  std::vector<std::string> problems;  // teardown/collection issues that did not change the outcome
};

std::string ResultJson(const TrialResult& result);

// Counts what happened, from the events of every log (pure).
class Metrics {
 public:
  void OnEvent(std::string_view component, const LogfmtFields& fields);
  // events_total, victims_detected, victims_confirmed (distinct `victim`), collisions, crashes,
  // leader_elections, and mission_complete_t_s when the mission completed.
  std::map<std::string, double> Values() const;

 private:
  std::uint64_t events_ = 0;
  std::uint64_t collisions_ = 0;
  std::uint64_t crashes_ = 0;
  std::uint64_t elections_ = 0;
  std::set<std::string> detected_;
  std::set<std::string> confirmed_;
  std::optional<double> mission_complete_t_s_;
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
