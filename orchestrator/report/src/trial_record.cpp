#include "swarmbox/report/trial_record.hpp"

#include <algorithm>
#include <array>
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

namespace {

// Where truth.csv's columns are; the velocity columns are optional (older recordings lack them).
struct TruthColumns {
  int t = -1, drone = -1, x = -1, y = -1, z = -1;
  int vx = -1, vy = -1, vz = -1;
  bool velocity = false;
  std::size_t need = 0;    // a row needs more cells than this
  std::size_t need_v = 0;  // ... and more than this for its velocity
  std::array<int, 7> attitude{-1, -1, -1, -1, -1, -1, -1};  // qw qx qy qz p q r
  bool has_attitude = false;
  std::size_t need_a = 0;  // ... and more than this for its attitude
};

// Splits `line` at every ',' into `cells` (views into line).
void SplitCells(std::string_view line, std::vector<std::string_view>& cells) {
  cells.clear();
  while (true) {
    const std::size_t comma = line.find(',');
    cells.push_back(line.substr(0, comma));
    if (comma == std::string_view::npos) return;
    line.remove_prefix(comma + 1);
  }
}

// The columns by name in the header line; nullopt without time, drone and position.
std::optional<TruthColumns> FindTruthColumns(const std::string& line) {
  std::vector<std::string> header;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) header.push_back(cell);
  auto col = [&](std::string_view name) -> int {
    auto it = std::find(header.begin(), header.end(), name);
    return it == header.end() ? -1 : static_cast<int>(it - header.begin());
  };
  TruthColumns c;
  c.t = col("t_s");
  c.drone = col("drone");
  c.x = col("x_m");
  c.y = col("y_m");
  c.z = col("z_m");
  c.vx = col("vx_m_s");
  c.vy = col("vy_m_s");
  c.vz = col("vz_m_s");
  if (c.t < 0 || c.drone < 0 || c.x < 0 || c.y < 0 || c.z < 0) return std::nullopt;
  c.velocity = c.vx >= 0 && c.vy >= 0 && c.vz >= 0;
  c.need = static_cast<std::size_t>(std::max({c.t, c.drone, c.x, c.y, c.z}));
  c.need_v = static_cast<std::size_t>(std::max({c.vx, c.vy, c.vz}));
  constexpr std::string_view kAttitude[] = {"qw", "qx", "qy", "qz", "p_rad_s", "q_rad_s", "r_rad_s"};
  for (std::size_t k = 0; k < c.attitude.size(); ++k) c.attitude[k] = col(kAttitude[k]);
  c.has_attitude = *std::min_element(c.attitude.begin(), c.attitude.end()) >= 0;
  c.need_a = static_cast<std::size_t>(*std::max_element(c.attitude.begin(), c.attitude.end()));
  return c;
}

// Fills `row` from one line's cells; false for a short or unparsable row (skipped). The
// velocity is kept only when all three of its cells parse.
bool ParseTruthRow(const std::vector<std::string_view>& cells, const TruthColumns& c, TruthRow& row) {
  if (cells.size() <= c.need) return false;
  auto num = [&](int i) { return yaml::ScalarAsDouble(cells[static_cast<std::size_t>(i)]); };
  auto t = num(c.t), x = num(c.x), y = num(c.y), z = num(c.z);
  if (!t || !x || !y || !z) return false;
  row.t_s = *t;
  row.drone.assign(cells[static_cast<std::size_t>(c.drone)]);
  row.x_m = *x;
  row.y_m = *y;
  row.z_m = *z;
  row.has_velocity = false;
  if (c.velocity && cells.size() > c.need_v) {
    auto vx = num(c.vx), vy = num(c.vy), vz = num(c.vz);
    if (vx && vy && vz) {
      row.vx_m_s = *vx;
      row.vy_m_s = *vy;
      row.vz_m_s = *vz;
      row.has_velocity = true;
    }
  }
  row.has_attitude = false;
  if (c.has_attitude && cells.size() > c.need_a) {
    double* dst[] = {&row.qw, &row.qx, &row.qy, &row.qz, &row.p_rad_s, &row.q_rad_s, &row.r_rad_s};
    row.has_attitude = true;
    for (std::size_t k = 0; k < c.attitude.size(); ++k) {
      const auto v = num(c.attitude[k]);
      if (!v) row.has_attitude = false;
      else *dst[k] = *v;
    }
  }
  return true;
}

}  // namespace

bool ReadTruthCsv(const std::string& path, const std::function<void(const TruthRow&)>& on_row) {
  std::ifstream in(path);
  if (!in) return false;
  std::string line;
  if (!std::getline(in, line)) return false;
  const std::optional<TruthColumns> columns = FindTruthColumns(line);
  if (!columns) return false;
  std::vector<std::string_view> cells;
  TruthRow row;
  while (std::getline(in, line)) {
    SplitCells(line, cells);
    if (ParseTruthRow(cells, *columns, row)) on_row(row);
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

namespace {

// The folder's logs/*.log, sorted by path.
std::vector<fs::path> SortedLogs(const fs::path& dir) {
  std::error_code ec;
  std::vector<fs::path> logs;
  for (const auto& e : fs::directory_iterator(dir / "logs", ec)) {
    if (e.path().extension() == ".log") logs.push_back(e.path());
  }
  std::sort(logs.begin(), logs.end());
  return logs;
}

// One record of events.jsonl: a process fault applied (its targets are lost from then on), or
// an orchestrator/fault component's event.
void OnEventsRecord(const Node& j, TrialMetrics& metrics) {
  if (StringAt(j, "type") == "fault") {
    // A process fault's record (faults/fault_event.hpp).
    const std::string kind = StringAt(j, "kind");
    const bool process = kind == "kill" || kind == "stop" || kind == "pause" || kind == "restart";
    if (StringAt(j, "phase") != "applied" || !process) return;
    for (const std::string& target : StringsAt(j, "targets")) {
      metrics.OnOrchestratorEvent(kind + "_fault", target, NumberAt(j, "t_sim_s"));
    }
    return;
  }
  const std::string component = StringAt(j, "component");
  if (component != "orchestrator" && component.find("fault") == std::string::npos) return;
  std::optional<double> t = NumberAt(j, "t");
  if (!t) t = NumberAt(j, "sim_s");
  metrics.OnOrchestratorEvent(StringAt(j, "event"), StringAt(j, "target"), t);
}

void ReadOrchestratorEvents(const fs::path& dir, TrialMetrics& metrics) {
  std::ifstream in(dir / "events.jsonl");
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("\"orchestrator\"") == std::string::npos && line.find("fault") == std::string::npos) {
      continue;  // agent/physics events are read from logs/
    }
    auto j = yaml::Parse(line, "events.jsonl");
    if (j && j->is_mapping()) OnEventsRecord(*j, metrics);
  }
}

// The world's victims (the runner writes the trial's world, generated or given, as world.yaml).
void ReadWorldVictims(const fs::path& dir, TrialMetrics& metrics) {
  auto world_text = ReadText(dir / "world.yaml");
  if (!world_text) return;
  auto world = yaml::Parse(*world_text, (dir / "world.yaml").string());
  if (!world || !world->is_mapping()) return;
  const yaml::Node* victims = world->Find("victims");
  if (victims == nullptr || !victims->is_sequence()) return;
  for (const yaml::Node& v : victims->items()) {
    const std::optional<double> x = NumberAt(v, "x_m"), y = NumberAt(v, "y_m");
    if (x && y) metrics.OnWorldVictim(*x, *y);
  }
}

}  // namespace

std::optional<MetricValues> ReadTrialMetrics(const std::string& dir_text) {
  const fs::path dir(dir_text);
  TrialMetrics metrics;
  const std::vector<fs::path> logs = SortedLogs(dir);
  if (logs.empty()) return std::nullopt;
  for (const fs::path& log : logs) {
    const std::string component = log.stem().string();
    if (component == "physics") metrics.SawPhysicsLog();
    std::ifstream in(log);
    std::string line;
    while (std::getline(in, line)) metrics.OnLogEvent(component, ParseLogfmt(line));
  }
  ReadOrchestratorEvents(dir, metrics);
  ReadTruthCsv((dir / "truth.csv").string(), [&](const TruthRow& r) {
    metrics.OnTruth(r.t_s, r.drone, r.x_m, r.y_m, r.z_m);
  });
  ReadWorldVictims(dir, metrics);
  return metrics.Values();
}

namespace {

// trial_meta.json when the experiment runner wrote one; else (a plain `swarmbox run` folder)
// what result.json says.
Status ReadTrialMeta(const fs::path& dir, const Node& result, TrialRecord& rec) {
  auto meta_text = ReadText(dir / "trial_meta.json");
  if (!meta_text) {
    rec.meta.id = StringAt(result, "trial_id").empty() ? rec.folder : StringAt(result, "trial_id");
    rec.meta.seed = static_cast<std::uint64_t>(NumberAt(result, "seed").value_or(0));
    return Ok{};
  }
  auto meta = ParseTrialMetaJson(*meta_text, (dir / "trial_meta.json").string());
  if (!meta) return meta.error();
  rec.meta = std::move(*meta);
  return Ok{};
}

// The metrics from logs/; with logs/ pruned, what the runner computed with the same definitions
// when it wrote result.json.
MetricValues ReadOrStoredMetrics(const fs::path& dir, const Node& result) {
  if (auto metrics = ReadTrialMetrics(dir.string())) return std::move(*metrics);
  MetricValues values;
  for (const std::string& name : MetricNames()) values[name] = std::nullopt;
  if (const Node* stored = result.Find("metrics"); stored != nullptr && stored->is_mapping()) {
    for (const std::string& name : MetricNames()) values[name] = NumberAt(*stored, name);
  }
  return values;
}

}  // namespace

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
  SWARMBOX_TRY(ReadTrialMeta(dir, *result, rec));
  rec.metrics = ReadOrStoredMetrics(dir, *result);
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
  for (const fs::path& log : SortedLogs(dir)) {
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
