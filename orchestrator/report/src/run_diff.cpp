#include "swarmbox/report/run_diff.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <tuple>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/split.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::report {

const std::vector<std::string_view> kIgnoredEventFields = {"rtf", "clock.late", "mechanism.detected",
                                                           "mechanism.host"};
const std::vector<std::string_view> kIgnoredEvents = {"joining", "joined"};

namespace {

constexpr std::string_view kRunPlaceholder = "<run>";

std::string_view SideName(Side s) { return s == Side::kA ? "A" : "B"; }

std::string Seconds(double t) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3f", t);
  return buf;
}

// Lines without their '\n' (and a '\r' before it); a last empty line is not a line.
std::vector<std::string_view> Lines(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back(line);
    pos = end + 1;
  }
  return lines;
}

std::optional<double> Number(std::string_view text) {
  if (text.empty()) return std::nullopt;
  return yaml::ScalarAsDouble(text);
}

std::string ReplaceAll(std::string text, std::string_view what, std::string_view with) {
  if (what.empty()) return text;
  for (std::size_t pos = text.find(what); pos != std::string::npos;
       pos = text.find(what, pos + with.size())) {
    text.replace(pos, what.size(), with);
  }
  return text;
}

// ---- result.json ----------------------------------------------------------------------------

struct ResultFacts {
  std::string outcome, reason, run_id, seed, trial;
  std::optional<double> end_t_s;  // the ending line's t
  std::string ending_line;
};

std::string StringAt(const yaml::Node& doc, std::string_view key) {
  const yaml::Node* n = doc.Find(key);
  return n != nullptr && n->is_scalar() ? n->scalar() : std::string();
}

Result<ResultFacts> ParseResult(std::string_view text, Side side) {
  const std::string where = "result.json of run " + std::string(SideName(side));
  auto doc = yaml::Parse(text, where);
  if (!doc) return Error(ErrorCode::kInvalidArgument, doc.error().message(), where);
  if (!doc->is_mapping()) return Error(ErrorCode::kInvalidArgument, "not a JSON object", where);
  ResultFacts r;
  r.outcome = StringAt(*doc, "outcome");
  r.reason = StringAt(*doc, "reason");
  r.run_id = StringAt(*doc, "run_id");
  r.seed = StringAt(*doc, "seed");
  r.trial = StringAt(*doc, "trial");
  r.ending_line = StringAt(*doc, "ending_line");
  if (!r.ending_line.empty()) {
    if (auto t = FindField(ParseLogfmt(r.ending_line), "t")) r.end_t_s = Number(*t);
  }
  return r;
}

// ---- truth.csv ------------------------------------------------------------------------------

struct TruthTable {
  std::vector<std::string_view> lines;  // header first
  std::vector<std::string_view> header;
  std::size_t t_col = 0, drone_col = 0;
  std::size_t rows = 0;                 // data rows within the horizon
};

Result<TruthTable> ParseTruth(std::string_view text, Side side, std::optional<double> horizon_s) {
  const std::string where = "truth.csv of run " + std::string(SideName(side));
  TruthTable t;
  t.lines = Lines(text);
  if (t.lines.empty()) return t;  // nothing written: compared as a file with no header and no row
  t.header = SplitOn(t.lines[0], ',');
  auto col = [&](std::string_view name) -> std::optional<std::size_t> {
    auto it = std::find(t.header.begin(), t.header.end(), name);
    if (it == t.header.end()) return std::nullopt;
    return static_cast<std::size_t>(it - t.header.begin());
  };
  auto tc = col("t_s");
  auto dc = col("drone");
  if (!tc || !dc) {
    return Error(ErrorCode::kInvalidArgument, "the header has no t_s or drone column", where + ":1");
  }
  t.t_col = *tc;
  t.drone_col = *dc;
  t.rows = t.lines.size() - 1;
  if (horizon_s) {
    for (std::size_t i = 1; i < t.lines.size(); ++i) {
      const auto cells = SplitOn(t.lines[i], ',');
      const auto ts = cells.size() > t.t_col ? Number(cells[t.t_col]) : std::nullopt;
      if (ts && *ts > *horizon_s) {
        t.rows = i - 1;
        break;
      }
    }
  }
  return t;
}

// The cells that differ, named by `names` where it has a name for the column, else "column N".
std::vector<FieldDiff> CellDiffs(const std::vector<std::string_view>& ca,
                                 const std::vector<std::string_view>& cb,
                                 const std::vector<std::string_view>& names) {
  std::vector<FieldDiff> fields;
  const std::size_t n = std::max(ca.size(), cb.size());
  for (std::size_t c = 0; c < n; ++c) {
    FieldDiff f{c < names.size() ? std::string(names[c]) : "column " + std::to_string(c + 1), std::nullopt,
                std::nullopt};
    if (c < ca.size()) f.a = std::string(ca[c]);
    if (c < cb.size()) f.b = std::string(cb[c]);
    if (f.a != f.b) fields.push_back(std::move(f));
  }
  return fields;
}

// The divergence at data row `row`: one file ended there (the other's row tells time and drone),
// or the two lines differ.
TruthDivergence RowDivergence(const TruthTable& a, const TruthTable& b, std::size_t row) {
  const bool end_a = row >= a.rows;
  const bool end_b = row >= b.rows;
  TruthDivergence d;
  d.line = row + 2;
  if (end_a || end_b) d.ended = end_a ? Side::kA : Side::kB;
  const auto ca = SplitOn((end_a ? b : a).lines[row + 1], ',');
  if (ca.size() > a.t_col) d.t_s = Number(ca[a.t_col]);
  if (ca.size() > a.drone_col) d.drone = std::string(ca[a.drone_col]);
  if (!d.ended) d.fields = CellDiffs(ca, SplitOn(b.lines[row + 1], ','), a.header);
  return d;
}

std::optional<TruthDivergence> CompareTruth(const TruthTable& a, const TruthTable& b,
                                            std::size_t* rows_alike) {
  const bool a_empty = a.lines.empty();
  const bool b_empty = b.lines.empty();
  if (a_empty || b_empty) {
    if (a_empty && b_empty) return std::nullopt;
    TruthDivergence d;
    d.line = 1;
    d.ended = a_empty ? Side::kA : Side::kB;
    return d;
  }
  if (a.header != b.header) {
    TruthDivergence d;
    d.line = 1;
    d.fields = CellDiffs(a.header, b.header, {});
    return d;
  }
  for (std::size_t row = 0;; ++row) {
    const bool end_a = row >= a.rows;
    const bool end_b = row >= b.rows;
    if (end_a && end_b) return std::nullopt;
    if (!end_a && !end_b && a.lines[row + 1] == b.lines[row + 1]) {
      *rows_alike = row + 1;
      continue;
    }
    return RowDivergence(a, b, row);
  }
}

// ---- events.jsonl ---------------------------------------------------------------------------

struct Event {
  std::size_t line = 0;
  std::string stream;
  std::optional<double> t_s;
  std::string json;                                        // as compared
  std::vector<std::pair<std::string, std::string>> fields;  // as compared, in order
};

bool HasWallWord(std::string_view name) {
  std::size_t pos = 0;
  while (pos <= name.size()) {
    std::size_t end = name.find('_', pos);
    if (end == std::string_view::npos) end = name.size();
    if (name.substr(pos, end - pos) == "wall") return true;
    pos = end + 1;
  }
  return false;
}

yaml::Node WithoutRun(const yaml::Node& node, const std::string& run_id) {
  if (node.is_scalar()) {
    if (run_id.empty() || node.scalar().find(run_id) == std::string::npos) return node;
    return yaml::Node::Scalar(ReplaceAll(node.scalar(), run_id, kRunPlaceholder), {}, /*quoted=*/true);
  }
  yaml::Node out = node;
  if (node.is_sequence()) {
    for (yaml::Node& item : out.items()) item = WithoutRun(item, run_id);
  } else if (node.is_mapping()) {
    for (auto& [key, value] : out.entries()) value = WithoutRun(value, run_id);
  }
  return out;
}

std::string ValueText(const yaml::Node& node) {
  return node.is_scalar() ? node.scalar() : yaml::EmitJson(node);
}

std::string StreamOf(const yaml::Node& doc) {
  const std::string component = StringAt(doc, "component");
  const std::string type = StringAt(doc, "type");
  if (!component.empty() && component != "orchestrator") return component;
  if (type == "fault") return "fault:" + StringAt(doc, "fault");
  if (!type.empty()) {
    const std::string node = StringAt(doc, "node");
    return node.empty() ? type : type + ":" + node;
  }
  if (component == "orchestrator") return "orchestrator:" + StringAt(doc, "target");
  return "-";
}

Result<std::vector<Event>> ParseEvents(std::string_view text, Side side, const std::string& run_id,
                                       std::optional<double> horizon_s) {
  const std::string where = "events.jsonl of run " + std::string(SideName(side));
  std::vector<Event> events;
  const auto lines = Lines(text);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].find_first_not_of(" \t") == std::string_view::npos) continue;
    const std::string at = where + ":" + std::to_string(i + 1);
    auto doc = yaml::Parse(lines[i], at);
    if (!doc || !doc->is_mapping()) {
      return Error(ErrorCode::kInvalidArgument,
                   doc ? std::string("not a JSON object") : doc.error().message(), at);
    }
    std::string kind = StringAt(*doc, "event");
    if (kind.empty()) kind = StringAt(*doc, "type");
    if (std::find(kIgnoredEvents.begin(), kIgnoredEvents.end(), kind) != kIgnoredEvents.end()) continue;
    Event e;
    e.line = i + 1;
    e.stream = StreamOf(*doc);
    const yaml::Node* t = doc->Find("t");
    if (t == nullptr) t = doc->Find("t_sim_s");
    if (t != nullptr && t->is_scalar()) e.t_s = Number(t->scalar());
    if (horizon_s && e.t_s && *e.t_s > *horizon_s) continue;
    yaml::Node kept = yaml::Node::Mapping();
    for (const auto& [key, value] : doc->entries()) {
      const std::string& name = key.scalar();
      if (IgnoredEventField(kind, name)) continue;
      yaml::Node v = WithoutRun(value, run_id);
      e.fields.emplace_back(name, ValueText(v));
      kept.Set(name, std::move(v));
    }
    e.json = yaml::EmitJson(kept);
    events.push_back(std::move(e));
  }
  return events;
}

using Streams = std::map<std::string, std::vector<const Event*>>;

Streams ByStream(const std::vector<Event>& events) {
  Streams s;
  for (const Event& e : events) s[e.stream].push_back(&e);
  return s;
}

std::vector<FieldDiff> EventFields(const Event& a, const Event& b) {
  std::vector<FieldDiff> out;
  auto find = [](const Event& e, const std::string& name) -> std::optional<std::string> {
    for (const auto& [n, v] : e.fields) {
      if (n == name) return v;
    }
    return std::nullopt;
  };
  for (const auto& [name, value] : a.fields) {
    auto other = find(b, name);
    if (other != value) out.push_back({name, value, other});
  }
  for (const auto& [name, value] : b.fields) {
    if (!find(a, name)) out.push_back({name, std::nullopt, value});
  }
  return out;
}

// The stream names of both runs: A's in order, then B's that A lacks.
std::vector<std::string> StreamNames(const Streams& sa, const Streams& sb) {
  std::vector<std::string> keys;
  for (const auto& [k, _] : sa) keys.push_back(k);
  for (const auto& [k, _] : sb) {
    if (sa.count(k) == 0) keys.push_back(k);
  }
  return keys;
}

// The divergence at position i of a stream (x or y nullptr: that run's stream ended). Its time
// is the earlier of the two events' times, else the last time both streams agreed on.
EventDivergence EventDivergenceAt(const std::string& stream, std::size_t i, const Event* x, const Event* y,
                                  std::optional<double> last_t) {
  EventDivergence d;
  d.stream = stream;
  d.index = i;
  std::optional<double> t;
  for (const Event* e : {x, y}) {
    if (e != nullptr && e->t_s && (!t || *e->t_s < *t)) t = e->t_s;
  }
  d.t_s = t ? t : last_t;
  if (x != nullptr) {
    d.line_a = x->line;
    d.event_a = x->json;
  }
  if (y != nullptr) {
    d.line_b = y->line;
    d.event_b = y->json;
  }
  if (x != nullptr && y != nullptr) d.fields = EventFields(*x, *y);
  return d;
}

// The first position where one stream's events differ between the runs.
std::optional<EventDivergence> FirstStreamDivergence(const std::string& stream,
                                                     const std::vector<const Event*>& ea,
                                                     const std::vector<const Event*>& eb) {
  std::optional<double> last_t;
  for (std::size_t i = 0; i < std::max(ea.size(), eb.size()); ++i) {
    const Event* x = i < ea.size() ? ea[i] : nullptr;
    const Event* y = i < eb.size() ? eb[i] : nullptr;
    if (x == nullptr || y == nullptr || x->json != y->json) return EventDivergenceAt(stream, i, x, y, last_t);
    if (x->t_s) last_t = x->t_s;
  }
  return std::nullopt;
}

// The earliest of the streams' first divergences: by time (timed before untimed), then line.
std::optional<EventDivergence> CompareEvents(const std::vector<Event>& a, const std::vector<Event>& b,
                                             std::size_t* streams) {
  const Streams sa = ByStream(a);
  const Streams sb = ByStream(b);
  const std::vector<std::string> keys = StreamNames(sa, sb);
  *streams = keys.size();
  static const std::vector<const Event*> kNone;
  std::optional<EventDivergence> best;
  auto rank = [](const EventDivergence& d) {
    const std::size_t line = d.line_a != 0 ? d.line_a : d.line_b;
    return std::make_tuple(d.t_s ? 0 : 1, d.t_s.value_or(0.0), line);
  };
  for (const std::string& key : keys) {
    auto ia = sa.find(key);
    auto ib = sb.find(key);
    std::optional<EventDivergence> d =
        FirstStreamDivergence(key, ia != sa.end() ? ia->second : kNone, ib != sb.end() ? ib->second : kNone);
    if (d && (!best || rank(*d) < rank(*best))) best = std::move(d);
  }
  return best;
}

std::string Quoted(const std::optional<std::string>& v) { return v ? *v : std::string("(none)"); }

void AppendFields(std::string* out, const std::vector<FieldDiff>& fields) {
  std::size_t width = 0;
  for (const FieldDiff& f : fields) width = std::max(width, f.field.size());
  for (const FieldDiff& f : fields) {
    *out += "  " + f.field + ":" + std::string(width - f.field.size() + 1, ' ') + Quoted(f.a) +
            " (A)  vs  " + Quoted(f.b) + " (B)\n";
  }
}

}  // namespace

bool IgnoredEventField(std::string_view kind, std::string_view name) {
  if (HasWallWord(name)) return true;
  for (std::string_view ignored : kIgnoredEventFields) {
    const std::size_t dot = ignored.find('.');
    if (dot == std::string_view::npos) {
      if (ignored == name) return true;
    } else if (ignored.substr(0, dot) == kind && ignored.substr(dot + 1) == name) {
      return true;
    }
  }
  return false;
}

std::optional<std::string> RunDiff::first_file() const {
  if (identical()) return std::nullopt;
  if (truth && truth->t_s && (!events || !events->t_s || *truth->t_s <= *events->t_s)) return "truth.csv";
  if (events && events->t_s) return "events.jsonl";
  if (truth) return "truth.csv";
  if (events) return "events.jsonl";
  if (!missing.empty()) return missing.front().file;
  return "result.json";
}

std::optional<double> RunDiff::first_t_s() const {
  const auto file = first_file();
  if (file == "truth.csv") return truth ? truth->t_s : std::nullopt;
  if (file == "events.jsonl") return events ? events->t_s : std::nullopt;
  return std::nullopt;
}

namespace {

// Records whether `file` is compared (in both runs) or missing from one; true when compared.
bool NoteCompared(RunDiff& diff, const std::string& file, bool in_a, bool in_b) {
  if (in_a && in_b) {
    diff.compared.push_back(file);
  } else if (in_a != in_b) {
    diff.missing.push_back({file, in_a ? Side::kB : Side::kA});
  }
  return in_a && in_b;
}

Result<std::optional<ResultFacts>> ParseResultIfAny(const std::optional<std::string>& text, Side side) {
  if (!text) return std::optional<ResultFacts>();
  auto r = ParseResult(*text, side);
  if (!r) return r.error();
  return std::optional<ResultFacts>(std::move(*r));
}

// The earlier of the two runs' ending lines bounds the comparison.
void SetHorizon(const std::optional<ResultFacts>& ra, const std::optional<ResultFacts>& rb, RunDiff& diff) {
  for (const auto& [r, side] : {std::pair{&ra, Side::kA}, std::pair{&rb, Side::kB}}) {
    if (*r && (*r)->end_t_s && (!diff.horizon_s || *(*r)->end_t_s < *diff.horizon_s)) {
      diff.horizon_s = (*r)->end_t_s;
      diff.horizon_reason = "the trial ended on '" + (*r)->ending_line + "' (run " +
                            std::string(SideName(side)) + ")";
    }
  }
}

Status DiffTruth(const std::string& a, const std::string& b, RunDiff& diff) {
  auto ta = ParseTruth(a, Side::kA, diff.horizon_s);
  if (!ta) return ta.error();
  auto tb = ParseTruth(b, Side::kB, diff.horizon_s);
  if (!tb) return tb.error();
  diff.truth = CompareTruth(*ta, *tb, &diff.truth_rows);
  return Ok{};
}

// run_id_a/b: each run's id, replaced by a placeholder in the events' values.
Status DiffEvents(const std::string& a, const std::string& b, const std::string& run_id_a,
                  const std::string& run_id_b, RunDiff& diff) {
  auto ea = ParseEvents(a, Side::kA, run_id_a, diff.horizon_s);
  if (!ea) return ea.error();
  auto eb = ParseEvents(b, Side::kB, run_id_b, diff.horizon_s);
  if (!eb) return eb.error();
  diff.events = CompareEvents(*ea, *eb, &diff.streams);
  diff.event_count = ea->size();
  return Ok{};
}

// Outcome and reason (run ids replaced) are divergences; other seeds or trials are notes.
void DiffResults(const ResultFacts& ra, const ResultFacts& rb, RunDiff& diff) {
  ResultDivergence r;
  if (ra.outcome != rb.outcome) r.fields.push_back({"outcome", ra.outcome, rb.outcome});
  const std::string reason_a = ReplaceAll(ra.reason, ra.run_id, kRunPlaceholder);
  const std::string reason_b = ReplaceAll(rb.reason, rb.run_id, kRunPlaceholder);
  if (reason_a != reason_b) r.fields.push_back({"reason", reason_a, reason_b});
  if (!r.fields.empty()) diff.result = std::move(r);
  if (ra.seed != rb.seed) diff.notes.push_back("the seeds differ: " + ra.seed + " (A), " + rb.seed + " (B)");
  if (ra.trial != rb.trial) {
    diff.notes.push_back("the trials differ: " + ra.trial + " (A), " + rb.trial + " (B)");
  }
}

}  // namespace

Result<RunDiff> DiffRuns(const RunFiles& a, const RunFiles& b) {
  RunDiff diff;
  auto ra = ParseResultIfAny(a.result_json, Side::kA);
  if (!ra) return ra.error();
  auto rb = ParseResultIfAny(b.result_json, Side::kB);
  if (!rb) return rb.error();
  SetHorizon(*ra, *rb, diff);
  if (NoteCompared(diff, "truth.csv", a.truth_csv.has_value(), b.truth_csv.has_value())) {
    SWARMBOX_TRY(DiffTruth(*a.truth_csv, *b.truth_csv, diff));
  }
  if (NoteCompared(diff, "events.jsonl", a.events_jsonl.has_value(), b.events_jsonl.has_value())) {
    SWARMBOX_TRY(DiffEvents(*a.events_jsonl, *b.events_jsonl, *ra ? (*ra)->run_id : "",
                            *rb ? (*rb)->run_id : "", diff));
  }
  if (NoteCompared(diff, "result.json", ra->has_value(), rb->has_value())) DiffResults(**ra, **rb, diff);
  return diff;
}

namespace {

// "identical: ..." or "differ: ...; first divergence in FILE at t=...".
std::string Headline(const RunDiff& d, const std::string& a, const std::string& b) {
  if (d.identical()) return "identical: A " + a + ", B " + b + "\n";
  std::string out = "differ: A " + a + ", B " + b + "; first divergence in " + *d.first_file();
  if (auto t = d.first_t_s()) out += " at t=" + Seconds(*t) + " s";
  return out + "\n";
}

std::string ComparedLine(const RunDiff& d) {
  std::string compared = "compared:";
  for (const std::string& f : d.compared) {
    compared += " " + f;
    if (f == "truth.csv") compared += " (" + std::to_string(d.truth_rows) + " rows alike)";
    if (f == "events.jsonl") {
      compared += " (" + std::to_string(d.event_count) + " events in " + std::to_string(d.streams) + " streams)";
    }
  }
  if (d.compared.empty()) compared += " nothing (no file is in both runs)";
  return compared + "\n";
}

std::string TruthDivergenceText(const TruthDivergence& t) {
  std::string out = "truth.csv line " + std::to_string(t.line);
  if (t.t_s) out += ", t=" + Seconds(*t.t_s) + " s";
  if (!t.drone.empty()) out += ", drone " + t.drone;
  if (t.ended) {
    const Side other = *t.ended == Side::kA ? Side::kB : Side::kA;
    return out + ": run " + std::string(SideName(*t.ended)) + "'s file ended first" +
           (t.line > 1 ? " (run " + std::string(SideName(other)) + " goes on with this row)" : "") + "\n";
  }
  out += (t.line == 1 ? ": the headers differ\n" : ":\n");
  AppendFields(&out, t.fields);
  return out;
}

std::string EventDivergenceText(const EventDivergence& e) {
  std::string out = "events.jsonl stream " + e.stream + ", event " + std::to_string(e.index + 1);
  if (e.t_s) out += ", t=" + Seconds(*e.t_s) + " s";
  out += " (line " + (e.line_a ? std::to_string(e.line_a) : std::string("-")) + " of A, line " +
         (e.line_b ? std::to_string(e.line_b) : std::string("-")) + " of B):\n";
  out += "  A: " + (e.event_a.empty() ? std::string("(the stream ended)") : e.event_a) + "\n";
  out += "  B: " + (e.event_b.empty() ? std::string("(the stream ended)") : e.event_b) + "\n";
  AppendFields(&out, e.fields);
  return out;
}

}  // namespace

std::string FormatRunDiff(const RunDiff& d, std::string_view name_a, std::string_view name_b) {
  std::string out = Headline(d, std::string(name_a), std::string(name_b)) + ComparedLine(d);
  if (d.horizon_s) out += "up to t=" + Seconds(*d.horizon_s) + " s: " + d.horizon_reason + "\n";
  for (const std::string& n : d.notes) out += "note: " + n + "\n";
  for (const MissingFile& m : d.missing) {
    out += m.file + ": not in run " + std::string(SideName(m.missing_in)) + "\n";
  }
  if (d.truth) out += TruthDivergenceText(*d.truth);
  if (d.events) out += EventDivergenceText(*d.events);
  if (d.result) {
    out += "result.json:\n";
    AppendFields(&out, d.result->fields);
  }
  return out;
}

}  // namespace swarmbox::report
