// The first divergence between two trial output folders (`swarmbox diff RUN_A RUN_B`): pure, it
// takes the files' contents (the CLI reads them) and says where the runs part.
//
//   RunFiles a{truth_a, events_a, result_a}, b{...};   // nullopt = the file is not in the folder
//   Result<RunDiff> d = DiffRuns(a, b);                 // error: a file that cannot be parsed
//   if (d->identical()) ...                             // exit 0
//   std::cout << FormatRunDiff(*d, "runs/a", "runs/b");
//
// What is compared, and what is not (the README and `swarmbox diff --help` say the same):
// - truth.csv: the header, then row by row in file order (one row per simulated time and drone);
//   the first row whose fields differ, with each differing column and both values, or which file
//   ended first.
// - events.jsonl: per stream, in file order. The file interleaves the streams in wall-clock
//   order, so it is split into streams first: a container's log events (by `component`), and the
//   orchestrator's records by subject (lifecycle records by `target`, fault records by `fault`,
//   mesh records by `node`, the mechanism record). The first differing event of each stream is
//   found; the one reported is the earliest by simulated time (`t`, or `t_sim_s` for orchestrator
//   records; a record without either takes the latest simulated time before it in its stream;
//   divergences without any simulated time come after the timed ones). Not compared, as
//   wall-clock by nature (kIgnoredEventFields): every field with `wall` as one of its
//   `_`-separated words (`wall_s`, `requested_wall_s`, ...), `rtf` (the pace asked for and
//   achieved: the wall clock against simulated time), `late` of `event=clock` (steps the pacing
//   missed on the wall clock), `detected` and `host` of the `mechanism` record (whether this
//   process probed the host or used its cache, and the machine's name); and whole events of the
//   kinds in kIgnoredEvents: `joining` and `joined`, the physics server's start progress (who had
//   answered the first step after each wall second of the start). The run id (result.json's
//   `run_id`, part of container names and paths) is replaced by `<run>` in every value first.
// - result.json: `outcome` and `reason` (nothing else: wall_s, sim_s at the moment the runner saw
//   the end, provenance and metrics are about the machine or follow from the files above).
// - The horizon: a trial that ended on a log line (result.json's `ending_line`, e.g.
//   `event=mission_complete`) is compared up to that line's simulated time (the earlier of the two
//   runs'): what the containers did between the end and their stop depends on how fast the stop
//   arrived. A trial ended by its simulated timeout needs none (the physics server stops at it).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::report {

// One run folder's files as read; nullopt when the file is not there.
struct RunFiles {
  std::optional<std::string> truth_csv;
  std::optional<std::string> events_jsonl;
  std::optional<std::string> result_json;
};

// Field names of events.jsonl never compared (besides every name with a `wall` word):
// "rtf", "clock.late" (event=clock only), "mechanism.detected", "mechanism.host" (type=mechanism).
extern const std::vector<std::string_view> kIgnoredEventFields;
// Event kinds of events.jsonl never compared: "joining", "joined" (physics start progress, on the
// wall clock; a drone lost at the start also has its drone_lost event, which is compared).
extern const std::vector<std::string_view> kIgnoredEvents;
// Whether events.jsonl field `name` of a record with `event` (or `type`) `kind` is ignored.
bool IgnoredEventField(std::string_view kind, std::string_view name);

struct FieldDiff {
  std::string field;
  std::optional<std::string> a;  // nullopt: the field is not in that run's row/event
  std::optional<std::string> b;
};

// Which run a one-sided fact is about.
enum class Side { kA, kB };

struct TruthDivergence {
  std::size_t line = 0;           // 1-based line number in both files (1 = the header)
  std::optional<double> t_s;      // the row's simulated time (the longer file's row when one ended)
  std::string drone;
  std::vector<FieldDiff> fields;  // empty when a file ended
  std::optional<Side> ended;      // the run whose truth.csv ended first (at `line`)
};

struct EventDivergence {
  std::string stream;             // "scout_1", "orchestrator:physics", "fault:kill_leader", ...
  std::optional<double> t_s;      // simulated time of the divergence (see the banner)
  std::size_t line_a = 0;         // 1-based line in events.jsonl; 0 = A's stream ended here
  std::size_t line_b = 0;
  std::string event_a;            // the event as compared (JSON, ignored fields removed); "" = ended
  std::string event_b;
  std::vector<FieldDiff> fields;  // empty when a stream ended
  std::size_t index = 0;          // 0-based position in the stream
};

struct ResultDivergence {
  std::vector<FieldDiff> fields;  // outcome, reason
};

// A file present in one run only.
struct MissingFile {
  std::string file;  // "truth.csv", "events.jsonl", "result.json"
  Side missing_in = Side::kA;
};

struct RunDiff {
  std::optional<TruthDivergence> truth;
  std::optional<EventDivergence> events;
  std::optional<ResultDivergence> result;
  std::vector<MissingFile> missing;
  std::optional<double> horizon_s;   // compared up to this simulated time (see the banner)
  std::string horizon_reason;        // "the trial ended on 't=..., node=... event=...' (run A)"
  // What was compared, for the summary.
  std::size_t truth_rows = 0;        // data rows compared (both runs alike up to there)
  std::size_t event_count = 0;       // events compared in A (within the horizon)
  std::size_t streams = 0;           // streams in A and B together
  std::vector<std::string> compared; // the files compared in both runs
  std::vector<std::string> notes;    // facts that are not divergences (different seeds, ...)

  bool identical() const { return !truth && !events && !result && missing.empty(); }
  // The file holding the earliest divergence ("truth.csv", "events.jsonl", "result.json", or the
  // missing file), and its simulated time; nullopt when identical.
  std::optional<std::string> first_file() const;
  std::optional<double> first_t_s() const;
};

// kInvalidArgument (with the file and line) when a file cannot be parsed: a truth.csv without its
// `t_s`/`drone` header, an events.jsonl line that is not a JSON object, a result.json that is not
// one.
Result<RunDiff> DiffRuns(const RunFiles& a, const RunFiles& b);

// The text `swarmbox diff` prints: one summary line, then each file's first divergence.
std::string FormatRunDiff(const RunDiff& diff, std::string_view name_a, std::string_view name_b);

}  // namespace swarmbox::report
