#include "trial_events.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::fault_trials {
namespace {

std::optional<double> ParseDouble(const std::string& text) {
  if (text.empty()) return std::nullopt;
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || ptr != end) return std::nullopt;
  return v;
}

std::uint64_t ParseU64(const std::string& text) {
  std::uint64_t v = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  return (ec == std::errc() && ptr == end) ? v : 0;
}

bool IsLink(const TrialEvent& e) { return e.Get("event") == "link"; }

}  // namespace

std::string TrialEvent::Get(std::string_view key) const {
  auto it = fields.find(std::string(key));
  return it == fields.end() ? std::string() : it->second;
}

std::optional<double> TrialEvent::Number(std::string_view key) const { return ParseDouble(Get(key)); }

Result<std::vector<TrialEvent>> ParseEvents(std::string_view jsonl) {
  std::vector<TrialEvent> out;
  std::size_t line_no = 0;
  while (!jsonl.empty()) {
    const std::size_t nl = jsonl.find('\n');
    const std::string_view line = jsonl.substr(0, nl);
    jsonl = nl == std::string_view::npos ? std::string_view() : jsonl.substr(nl + 1);
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) continue;
    auto doc = yaml::Parse(line, "events.jsonl");
    if (!doc || !doc->is_mapping()) {
      return Error(ErrorCode::kProtocol, "not a JSON object",
                   "events.jsonl:" + std::to_string(line_no));
    }
    TrialEvent e;
    for (const auto& [k, v] : doc->entries()) {
      if (!k.is_scalar()) continue;
      if (v.is_scalar()) {
        e.fields[k.scalar()] = v.scalar();
      } else if (v.is_sequence() && k.scalar() == "targets") {
        for (const yaml::Node& t : v.items()) {
          if (t.is_scalar()) e.targets.push_back(t.scalar());
        }
      }
    }
    e.wall_s = e.Number("wall_s").value_or(0.0);
    e.component = e.Get("component");
    out.push_back(std::move(e));
  }
  return out;
}

Result<std::vector<TrialEvent>> ReadEvents(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Error(ErrorCode::kNotFound, "cannot open", path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseEvents(ss.str());
}

std::optional<TrialEvent> FindFaultRecord(const std::vector<TrialEvent>& events,
                                          std::string_view fault_id, std::string_view phase) {
  for (const TrialEvent& e : events) {
    if (e.Get("type") == "fault" && e.Get("fault") == fault_id && e.Get("phase") == phase) return e;
  }
  return std::nullopt;
}

LinkSummary SummariseLinks(const std::vector<TrialEvent>& events, double from_s, double to_s) {
  LinkSummary s;
  std::map<std::pair<std::string, std::string>, bool> contact;
  // Pooled moments: sum of n, of n * mean, and of (n - 1) sd^2 + n mean^2 (= sum of squares).
  double n_total = 0.0, sum = 0.0, sum_sq = 0.0;
  std::vector<double> p50s, sds;
  double sd_pongs = 0.0;
  for (const TrialEvent& e : events) {
    if (!IsLink(e)) continue;
    const auto key = std::make_pair(e.Get("node"), e.Get("peer"));
    const std::uint64_t sent = ParseU64(e.Get("sent"));
    const std::uint64_t received = ParseU64(e.Get("received"));
    bool& heard = contact[key];
    const bool skip = !heard;  // this and earlier windows of the pair straddle discovery
    heard = heard || received > 0;
    if (skip || e.wall_s < from_s || e.wall_s >= to_s) continue;
    ++s.windows;
    s.sent += sent;
    s.received += received;
    s.sent_by_node[key.first] += sent;
    if (received == 0) continue;
    const double n = static_cast<double>(received);
    const double mean = e.Number("rtt_ms_mean").value_or(0.0);
    const double sd = e.Number("rtt_ms_sd").value_or(0.0);
    n_total += n;
    sum += n * mean;
    sum_sq += (n - 1.0) * sd * sd + n * mean * mean;
    if (auto p50 = e.Number("rtt_ms_p50")) p50s.push_back(*p50);
    if (received >= kMinPongsForSd) {
      sds.push_back(sd);
      sd_pongs += n;
    }
  }
  if (s.sent > 0) {
    s.loss = 1.0 - static_cast<double>(s.received) / static_cast<double>(s.sent);
  }
  if (n_total > 0.0) {
    s.rtt_mean_ms = sum / n_total;
    if (n_total > 1.0) {
      s.rtt_sd_ms = std::sqrt(std::max(0.0, (sum_sq - n_total * s.rtt_mean_ms * s.rtt_mean_ms) /
                                                (n_total - 1.0)));
    }
    s.rtt_p50_ms = Percentile(p50s, 0.5);
  }
  if (!sds.empty()) {
    s.sd_windows = sds.size();
    s.pongs_per_sd_window = sd_pongs / static_cast<double>(sds.size());
    s.rtt_sd_window_median_ms = Percentile(sds, 0.5);
  }
  return s;
}

std::vector<Failover> Failovers(const std::vector<TrialEvent>& events) {
  std::vector<Failover> out;
  for (std::size_t i = 0; i < events.size(); ++i) {
    const TrialEvent& f = events[i];
    if (f.Get("type") != "fault" || f.Get("phase") != "applied") continue;
    const std::string kind = f.Get("kind");
    if ((kind != "kill" && kind != "stop") || f.targets.size() != 1) continue;
    // The leader at the time: the latest leader_elected before the fault.
    std::string leader;
    std::uint64_t term = 0;
    for (std::size_t j = 0; j < i; ++j) {
      const TrialEvent& e = events[j];
      if (e.Get("event") != "leader_elected") continue;
      const std::uint64_t t = ParseU64(e.Get("term"));
      if (t >= term) {
        term = t;
        leader = e.Get("leader");
      }
    }
    if (leader != f.targets[0]) continue;
    Failover fo;
    fo.fault = f.Get("fault");
    fo.old_leader = leader;
    fo.old_term = term;
    fo.fault_wall_s = f.wall_s;
    for (std::size_t j = i + 1; j < events.size(); ++j) {
      const TrialEvent& e = events[j];
      if (e.Get("event") != "leader_elected") continue;
      const std::uint64_t t = ParseU64(e.Get("term"));
      if (t <= term || e.Get("leader") == leader) continue;
      fo.new_leader = e.Get("leader");
      fo.new_term = t;
      fo.failover_ms = (e.wall_s - f.wall_s) * 1000.0;
      break;
    }
    out.push_back(fo);
  }
  return out;
}

std::map<std::string, std::vector<Commit>> CommitsByDrone(const std::vector<TrialEvent>& events) {
  std::map<std::string, std::vector<Commit>> out;
  for (const TrialEvent& e : events) {
    const std::string ev = e.Get("event");
    if (ev != "mission_state" && ev != "victim_confirmed" && ev != "victim_status") continue;
    if (e.Get("index").empty() || e.Get("from") == "snapshot") continue;
    Commit c;
    c.wall_s = e.wall_s;
    c.index = ParseU64(e.Get("index"));
    c.what = ev;
    for (const char* key : {"state", "id", "status", "rescuer"}) {
      const std::string v = e.Get(key);
      if (!v.empty()) c.what += std::string(" ") + key + "=" + v;
    }
    out[e.Get("node")].push_back(std::move(c));
  }
  return out;
}

std::uint64_t IndexAt(const std::vector<Commit>& commits, double at_s) {
  std::uint64_t index = 0;
  for (const Commit& c : commits) {
    if (c.wall_s <= at_s) index = std::max(index, c.index);
  }
  return index;
}

std::vector<std::string> Disagreements(const std::map<std::string, std::vector<Commit>>& commits) {
  // index -> the first drone that applied something there, and what (several events may share an
  // index: compare the joined list).
  std::map<std::uint64_t, std::map<std::string, std::string>> at;
  for (const auto& [drone, list] : commits) {
    for (const Commit& c : list) {
      std::string& s = at[c.index][drone];
      s += (s.empty() ? "" : "; ") + c.what;
    }
  }
  std::vector<std::string> out;
  for (const auto& [index, by_drone] : at) {
    const auto& [first_drone, first] = *by_drone.begin();
    for (const auto& [drone, what] : by_drone) {
      if (what != first) {
        out.push_back("index " + std::to_string(index) + ": " + first_drone + " '" + first +
                      "' vs " + drone + " '" + what + "'");
      }
    }
  }
  return out;
}

std::optional<std::string> LeaderSeenBy(const std::vector<TrialEvent>& events,
                                        const std::vector<std::string>& nodes, double at_s) {
  std::optional<std::string> leader;
  for (const TrialEvent& e : events) {
    if (e.wall_s > at_s || e.Get("event") != "leader_elected") continue;
    if (std::find(nodes.begin(), nodes.end(), e.Get("node")) == nodes.end()) continue;
    leader = e.Get("leader");
  }
  return leader;
}

std::vector<ClockLine> ClockLines(const std::vector<TrialEvent>& events) {
  std::vector<ClockLine> out;
  for (const TrialEvent& e : events) {
    if (e.Get("event") != "clock") continue;
    ClockLine c;
    c.wall_s = e.wall_s;
    c.t_s = e.Number("t").value_or(0.0);
    c.rtf = e.Number("rtf").value_or(0.0);
    c.late = ParseU64(e.Get("late"));
    c.lost = ParseU64(e.Get("lost"));
    out.push_back(c);
  }
  return out;
}

std::size_t CountEvents(const std::vector<TrialEvent>& events, std::string_view event) {
  return static_cast<std::size_t>(std::count_if(
      events.begin(), events.end(), [&](const TrialEvent& e) { return e.Get("event") == event; }));
}

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return -1.0;
  std::sort(values.begin(), values.end());
  const double rank = std::ceil(p * static_cast<double>(values.size()));
  const auto index = static_cast<std::size_t>(std::max(rank, 1.0)) - 1;
  return values[std::min(index, values.size() - 1)];
}

}  // namespace swarmbox::fault_trials
