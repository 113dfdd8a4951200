// swarmbox diff RUN_A RUN_B [--json]: the first divergence between two trial folders (truth.csv,
// events.jsonl without its wall-clock fields, result.json's outcome and reason), compared by
// report::DiffRuns (run_diff.hpp says exactly what is and is not compared). Exit 0 identical,
// 1 they differ, 2 a folder that is not a trial folder or a file that cannot be read or parsed.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "json_out.hpp"
#include "swarmbox/report/run_diff.hpp"

namespace swarmbox::cli {

namespace {

namespace fs = std::filesystem;

// nullopt when the file is not there; an error when it is there but cannot be read.
Result<std::optional<std::string>> ReadIfThere(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::optional<std::string>();
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in.good() && !in.eof()) return Error(ErrorCode::kIo, "cannot read", path.string());
  if (!in.is_open()) return Error(ErrorCode::kIo, "cannot open", path.string());
  return std::optional<std::string>(text.str());
}

Result<report::RunFiles> ReadRun(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return Error(ErrorCode::kInvalidArgument, "not a folder", dir);
  report::RunFiles files;
  for (auto [name, slot] : {std::pair{"truth.csv", &files.truth_csv},
                            std::pair{"events.jsonl", &files.events_jsonl},
                            std::pair{"result.json", &files.result_json}}) {
    auto text = ReadIfThere(fs::path(dir) / name);
    if (!text) return text.error();
    *slot = std::move(*text);
  }
  if (!files.truth_csv && !files.events_jsonl && !files.result_json) {
    return Error(ErrorCode::kInvalidArgument,
                 "not a trial folder (no truth.csv, events.jsonl or result.json)", dir);
  }
  return files;
}

yaml::Node Opt(const std::optional<std::string>& v) { return v ? json::Str(*v) : yaml::Node::Null(); }
yaml::Node OptNum(const std::optional<double>& v) { return v ? json::Num(*v) : yaml::Node::Null(); }
yaml::Node SideName(report::Side s) { return json::Str(s == report::Side::kA ? "a" : "b"); }

// A JSON list of `items`, each as `to_json` writes it.
template <typename T, typename ToJson>
yaml::Node ListJson(const std::vector<T>& items, ToJson to_json) {
  yaml::Node list = yaml::Node::Sequence();
  for (const T& item : items) list.Append(to_json(item));
  return list;
}

yaml::Node Fields(const std::vector<report::FieldDiff>& fields) {
  return ListJson(fields, [](const report::FieldDiff& f) {
    yaml::Node o = yaml::Node::Mapping();
    o.Set("field", json::Str(f.field));
    o.Set("a", Opt(f.a));
    o.Set("b", Opt(f.b));
    return o;
  });
}

yaml::Node MissingJson(const std::vector<report::MissingFile>& missing) {
  return ListJson(missing, [](const report::MissingFile& m) {
    yaml::Node x = yaml::Node::Mapping();
    x.Set("file", json::Str(m.file));
    x.Set("missing_in", SideName(m.missing_in));
    return x;
  });
}

yaml::Node TruthJson(const report::TruthDivergence& truth) {
  yaml::Node t = yaml::Node::Mapping();
  t.Set("line", json::Int(static_cast<std::int64_t>(truth.line)));
  t.Set("t_s", OptNum(truth.t_s));
  t.Set("drone", json::Str(truth.drone));
  t.Set("fields", Fields(truth.fields));
  t.Set("ended", truth.ended ? SideName(*truth.ended) : yaml::Node::Null());
  return t;
}

yaml::Node EventsJson(const report::EventDivergence& events) {
  yaml::Node e = yaml::Node::Mapping();
  e.Set("stream", json::Str(events.stream));
  e.Set("index", json::Int(static_cast<std::int64_t>(events.index)));
  e.Set("t_s", OptNum(events.t_s));
  e.Set("line_a", events.line_a ? json::Int(static_cast<std::int64_t>(events.line_a)) : yaml::Node::Null());
  e.Set("line_b", events.line_b ? json::Int(static_cast<std::int64_t>(events.line_b)) : yaml::Node::Null());
  e.Set("event_a", events.event_a.empty() ? yaml::Node::Null() : json::Str(events.event_a));
  e.Set("event_b", events.event_b.empty() ? yaml::Node::Null() : json::Str(events.event_b));
  e.Set("fields", Fields(events.fields));
  return e;
}

yaml::Node DiffJson(const report::RunDiff& d, const DiffArgs& args, int exit_code) {
  yaml::Node o = yaml::Node::Mapping();
  o.Set("a", json::Str(args.run_a));
  o.Set("b", json::Str(args.run_b));
  o.Set("identical", json::Bool(d.identical()));
  o.Set("first_file", Opt(d.first_file()));
  o.Set("first_t_s", OptNum(d.first_t_s()));
  o.Set("compared", json::Strs(d.compared));
  o.Set("horizon_s", OptNum(d.horizon_s));
  o.Set("truth_rows_alike", json::Int(static_cast<std::int64_t>(d.truth_rows)));
  o.Set("events", json::Int(static_cast<std::int64_t>(d.event_count)));
  o.Set("streams", json::Int(static_cast<std::int64_t>(d.streams)));
  o.Set("missing", MissingJson(d.missing));
  o.Set("truth", d.truth ? TruthJson(*d.truth) : yaml::Node::Null());
  o.Set("events_divergence", d.events ? EventsJson(*d.events) : yaml::Node::Null());
  o.Set("result", d.result ? Fields(d.result->fields) : yaml::Node::Null());
  o.Set("notes", json::Strs(d.notes));
  o.Set("exit_code", json::Int(exit_code));
  return o;
}

}  // namespace

int DiffCommand(const DiffArgs& args) {
  auto a = ReadRun(args.run_a);
  if (!a) {
    std::cerr << "swarmbox diff: " << a.error().ToString() << "\n";
    return kExitUsage;
  }
  auto b = ReadRun(args.run_b);
  if (!b) {
    std::cerr << "swarmbox diff: " << b.error().ToString() << "\n";
    return kExitUsage;
  }
  auto diff = report::DiffRuns(*a, *b);
  if (!diff) {
    std::cerr << "swarmbox diff: " << diff.error().ToString() << "\n";
    return kExitUsage;
  }
  const int code = diff->identical() ? kExitOk : kExitOutcome;
  if (args.json) {
    json::Print(DiffJson(*diff, args, code));
  } else {
    std::cout << report::FormatRunDiff(*diff, args.run_a, args.run_b);
  }
  return code;
}

}  // namespace swarmbox::cli
