#include "swarmbox/report/trial_record.hpp"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <fstream>
#include <sstream>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::report {

namespace fs = std::filesystem;
using yaml::Node;

namespace {

Node Str(std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); }
Node Bare(std::string s) { return Node::Scalar(std::move(s)); }

Node StrList(const std::vector<std::string>& items) {
  Node n = Node::Sequence();
  for (const std::string& s : items) n.Append(Str(s));
  return n;
}

Result<std::string> ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error(ErrorCode::kNotFound, "cannot read", path.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::optional<double> NumberAt(const Node& doc, std::string_view key) {
  const Node* n = doc.Find(key);
  if (n == nullptr || !n->is_scalar()) return std::nullopt;
  return yaml::ScalarAsDouble(n->scalar());
}

std::string StringAt(const Node& doc, std::string_view key) {
  const Node* n = doc.Find(key);
  return n != nullptr && n->is_scalar() ? n->scalar() : std::string();
}

std::vector<std::string> StringsAt(const Node& doc, std::string_view key) {
  std::vector<std::string> out;
  if (const Node* n = doc.Find(key); n != nullptr && n->is_sequence()) {
    for (const Node& item : n->items()) out.push_back(item.scalar());
  }
  return out;
}

}  // namespace

bool ReadTruthCsv(const std::string& path, const std::function<void(const TruthRow&)>& on_row) {
  std::ifstream in(path);
  if (!in) return false;
  std::string line;
  if (!std::getline(in, line)) return false;
  std::vector<std::string> header;
  {
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) header.push_back(cell);
  }
  auto col = [&](std::string_view name) -> int {
    auto it = std::find(header.begin(), header.end(), name);
    return it == header.end() ? -1 : static_cast<int>(it - header.begin());
  };
  const int ct = col("t_s"), cd = col("drone"), cx = col("x_m"), cy = col("y_m"), cz = col("z_m");
  const int cvx = col("vx_m_s"), cvy = col("vy_m_s"), cvz = col("vz_m_s");
  if (ct < 0 || cd < 0 || cx < 0 || cy < 0 || cz < 0) return false;
  const bool velocity = cvx >= 0 && cvy >= 0 && cvz >= 0;
  const auto need = static_cast<std::size_t>(std::max({ct, cd, cx, cy, cz}));
  const auto need_v = static_cast<std::size_t>(std::max({cvx, cvy, cvz}));
  std::vector<std::string_view> cells;
  TruthRow row;
  while (std::getline(in, line)) {
    cells.clear();
    std::string_view rest(line);
    while (true) {
      const std::size_t comma = rest.find(',');
      cells.push_back(rest.substr(0, comma));
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
    if (cells.size() <= need) continue;
    auto num = [&](int c) { return yaml::ScalarAsDouble(cells[static_cast<std::size_t>(c)]); };
    auto t = num(ct), x = num(cx), y = num(cy), z = num(cz);
    if (!t || !x || !y || !z) continue;
    row.t_s = *t;
    row.drone.assign(cells[static_cast<std::size_t>(cd)]);
    row.x_m = *x;
    row.y_m = *y;
    row.z_m = *z;
    row.has_velocity = false;
    if (velocity && cells.size() > need_v) {
      auto vx = num(cvx), vy = num(cvy), vz = num(cvz);
      if (vx && vy && vz) {
        row.vx_m_s = *vx;
        row.vy_m_s = *vy;
        row.vz_m_s = *vz;
        row.has_velocity = true;
      }
    }
    on_row(row);
  }
  return true;
}

std::string TrialMetaJson(const TrialMeta& m) {
  Node doc = Node::Mapping();
  doc.Set("id", Str(m.id));
  doc.Set("code", Str(m.code));
  doc.Set("factors", StrList(m.factors));
  doc.Set("levels", StrList(m.levels));
  doc.Set("repetition", Bare(std::to_string(m.repetition)));
  doc.Set("seed", Bare(std::to_string(m.seed)));
  doc.Set("attempts", Bare(std::to_string(m.attempts)));
  doc.Set("hosts", StrList(m.hosts));
  return yaml::EmitJson(doc) + "\n";
}

Result<TrialMeta> ParseTrialMetaJson(std::string_view text, std::string_view where) {
  auto doc = yaml::Parse(text, where);
  if (!doc) return doc.error();
  if (!doc->is_mapping()) return Error(ErrorCode::kProtocol, "expected a JSON object", std::string(where));
  TrialMeta m;
  m.id = StringAt(*doc, "id");
  m.code = StringAt(*doc, "code");
  m.factors = StringsAt(*doc, "factors");
  m.levels = StringsAt(*doc, "levels");
  m.repetition = static_cast<int>(NumberAt(*doc, "repetition").value_or(1));
  m.seed = static_cast<std::uint64_t>(NumberAt(*doc, "seed").value_or(0));
  m.attempts = static_cast<int>(NumberAt(*doc, "attempts").value_or(1));
  m.hosts = StringsAt(*doc, "hosts");
  if (m.id.empty()) return Error(ErrorCode::kProtocol, "no \"id\"", std::string(where));
  return m;
}

std::optional<MetricValues> ReadTrialMetrics(const std::string& dir_text) {
  const fs::path dir(dir_text);
  TrialMetrics metrics;
  std::error_code ec;
  std::vector<fs::path> logs;
  for (const auto& e : fs::directory_iterator(dir / "logs", ec)) {
    if (e.path().extension() == ".log") logs.push_back(e.path());
  }
  if (logs.empty()) return std::nullopt;
  std::sort(logs.begin(), logs.end());
  for (const fs::path& log : logs) {
    const std::string component = log.stem().string();
    if (component == "physics") metrics.SawPhysicsLog();
    std::ifstream in(log);
    std::string line;
    while (std::getline(in, line)) metrics.OnLogEvent(component, ParseLogfmt(line));
  }
  {
    std::ifstream in(dir / "events.jsonl");
    std::string line;
    while (std::getline(in, line)) {
      if (line.find("\"orchestrator\"") == std::string::npos &&
          line.find("fault") == std::string::npos) {
        continue;  // agent/physics events are read from logs/
      }
      auto j = yaml::Parse(line, "events.jsonl");
      if (!j || !j->is_mapping()) continue;
      if (StringAt(*j, "type") == "fault") {
        // A process fault's record (faults/fault_event.hpp): its targets are lost from the time
        // it was applied.
        const std::string kind = StringAt(*j, "kind");
        const bool process = kind == "kill" || kind == "stop" || kind == "pause" || kind == "restart";
        if (StringAt(*j, "phase") != "applied" || !process) continue;
        for (const std::string& target : StringsAt(*j, "targets")) {
          metrics.OnOrchestratorEvent(kind + "_fault", target, NumberAt(*j, "t_sim_s"));
        }
        continue;
      }
      const std::string component = StringAt(*j, "component");
      if (component != "orchestrator" && component.find("fault") == std::string::npos) continue;
      std::optional<double> t = NumberAt(*j, "t");
      if (!t) t = NumberAt(*j, "sim_s");
      metrics.OnOrchestratorEvent(StringAt(*j, "event"), StringAt(*j, "target"), t);
    }
  }
  ReadTruthCsv((dir / "truth.csv").string(), [&](const TruthRow& r) {
    metrics.OnTruth(r.t_s, r.drone, r.x_m, r.y_m, r.z_m);
  });
  // The world's victims (the runner writes the trial's world, generated or given, as world.yaml).
  if (auto world_text = ReadText(dir / "world.yaml")) {
    if (auto world = yaml::Parse(*world_text, (dir / "world.yaml").string()); world && world->is_mapping()) {
      if (const yaml::Node* victims = world->Find("victims"); victims != nullptr && victims->is_sequence()) {
        for (const yaml::Node& v : victims->items()) {
          const std::optional<double> x = NumberAt(v, "x_m"), y = NumberAt(v, "y_m");
          if (x && y) metrics.OnWorldVictim(*x, *y);
        }
      }
    }
  }
  return metrics.Values();
}

Result<TrialRecord> ReadTrialFolder(const std::string& dir_text) {
  const fs::path dir(dir_text);
  TrialRecord rec;
  rec.folder = dir.filename().string();
  auto result_text = ReadText(dir / "result.json");
  if (!result_text) return Error(ErrorCode::kNotFound, "no result.json", dir.string());
  auto result = yaml::Parse(*result_text, (dir / "result.json").string());
  if (!result) return result.error();
  if (!result->is_mapping()) {
    return Error(ErrorCode::kProtocol, "result.json is not an object", dir.string());
  }
  rec.outcome = StringAt(*result, "outcome");
  rec.reason = StringAt(*result, "reason");
  rec.host = StringAt(*result, "host");
  rec.wall_s = NumberAt(*result, "wall_s");
  rec.sim_s = NumberAt(*result, "sim_s");
  if (auto meta_text = ReadText(dir / "trial_meta.json")) {
    auto meta = ParseTrialMetaJson(*meta_text, (dir / "trial_meta.json").string());
    if (!meta) return meta.error();
    rec.meta = std::move(*meta);
  } else {
    // A plain `swarmbox run` folder: what result.json says.
    rec.meta.id = StringAt(*result, "trial_id").empty() ? rec.folder : StringAt(*result, "trial_id");
    rec.meta.seed = static_cast<std::uint64_t>(NumberAt(*result, "seed").value_or(0));
  }

  if (auto metrics = ReadTrialMetrics(dir.string())) {
    rec.metrics = std::move(*metrics);
  } else {
    // logs/ pruned: what the runner computed with the same definitions when it wrote result.json.
    for (const std::string& name : MetricNames()) rec.metrics[name] = std::nullopt;
    if (const Node* stored = result->Find("metrics"); stored != nullptr && stored->is_mapping()) {
      for (const std::string& name : MetricNames()) rec.metrics[name] = NumberAt(*stored, name);
    }
  }
  if (const Node* p = result->Find("provenance"); p != nullptr) rec.provenance = ParseProvenance(*p);
  std::error_code ec;
  rec.has_trajectories = fs::exists(dir / "trajectories.png", ec);
  rec.has_plots = fs::exists(dir / "plots.html", ec);
  return rec;
}

TrialSeries ReadTrialSeries(const std::string& dir_text, bool* found) {
  const fs::path dir(dir_text);
  TrialSeriesBuilder builder;
  bool any = false;
  std::error_code ec;
  std::vector<fs::path> logs;
  for (const auto& e : fs::directory_iterator(dir / "logs", ec)) {
    if (e.path().extension() == ".log") logs.push_back(e.path());
  }
  std::sort(logs.begin(), logs.end());
  for (const fs::path& log : logs) {
    const std::string component = log.stem().string();
    std::ifstream in(log);
    std::string line;
    while (std::getline(in, line)) {
      any = true;
      builder.OnLogEvent(component, ParseLogfmt(line));
    }
  }
  ReadTruthCsv((dir / "truth.csv").string(), [&](const TruthRow& r) {
    any = true;
    builder.OnTruth(r);
  });
  if (found != nullptr) *found = any;
  return builder.Finish();
}

Result<bool> WriteTrialPlots(const std::string& dir, const TrialPlotsPage& page) {
  bool found = false;
  const TrialSeries series = ReadTrialSeries(dir, &found);
  if (!found) return false;
  const fs::path path = fs::path(dir) / "plots.html";
  const fs::path tmp = fs::path(dir) / ".plots.html.tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << TrialPlotsHtml(page, series);
    if (!out) return Error(ErrorCode::kIo, "cannot write", tmp.string());
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) return Error(ErrorCode::kIo, "cannot rename to plots.html: " + ec.message(), path.string());
  return true;
}

std::vector<TrialRecord> ReadExperimentFolder(const std::string& dir,
                                              std::vector<std::string>* problems) {
  std::vector<TrialRecord> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (!e.is_directory() || e.path().filename().string().front() == '.') continue;
    if (!fs::exists(e.path() / "result.json")) continue;
    auto rec = ReadTrialFolder(e.path().string());
    if (rec) {
      out.push_back(std::move(*rec));
    } else if (problems != nullptr) {
      problems->push_back(rec.error().ToString());
    }
  }
  std::sort(out.begin(), out.end(),
            [](const TrialRecord& a, const TrialRecord& b) { return a.meta.id < b.meta.id; });
  return out;
}

std::string ExperimentTitle(const std::string& dir) {
  if (auto text = ReadText(fs::path(dir) / "experiment.json")) {
    if (auto doc = yaml::Parse(*text, "experiment.json"); doc && doc->is_mapping()) {
      if (std::string name = StringAt(*doc, "name"); !name.empty()) return name;
    }
  }
  std::string title = fs::path(dir).lexically_normal().filename().string();
  if (title.empty() || title == ".") title = fs::path(dir).lexically_normal().parent_path().filename().string();
  return title.empty() ? dir : title;
}

std::vector<std::string> FactorNames(const std::string& dir, const std::vector<TrialRecord>& records) {
  if (auto text = ReadText(fs::path(dir) / "experiment.json")) {
    if (auto doc = yaml::Parse(*text, "experiment.json"); doc && doc->is_mapping()) {
      return StringsAt(*doc, "factors");
    }
  }
  for (const TrialRecord& r : records) {
    if (!r.meta.factors.empty()) return r.meta.factors;
  }
  return {};
}

}  // namespace swarmbox::report
