#include "swarm_figures.hpp"

#include <algorithm>
#include <cstdio>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::swarm {

namespace {

std::optional<double> Number(const yaml::Node* n) {
  if (n == nullptr || !n->is_scalar()) return std::nullopt;
  auto v = n->AsDouble();
  return v ? std::optional<double>(*v) : std::nullopt;
}

std::string Text(const yaml::Node* n) { return n != nullptr && n->is_scalar() ? n->scalar() : std::string(); }

std::string Fixed(std::optional<double> v, int decimals) {
  if (!v) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, *v);
  return buf;
}

// The largest simulated time of the lines logged by wall time `wall_s` (events.jsonl is in the
// order the runner read the lines; a line's t is its component's simulated time).
double SimTimeBy(const std::vector<std::string>& events, double wall_s) {
  double t_max = 0;
  for (const std::string& line : events) {
    auto doc = yaml::Parse(line, "events.jsonl");
    if (!doc || !doc->is_mapping()) continue;
    const std::optional<double> wall = Number(doc->Find("wall_s"));
    const std::optional<double> t = Number(doc->Find("t"));
    if (wall && t && *wall <= wall_s) t_max = std::max(t_max, *t);
  }
  return t_max;
}

// The agents' summed CPU time at one sample; nullopt unless every drone is in it.
std::optional<double> AgentCpuAt(const CgroupSnapshot& sample, const std::vector<std::string>& drones) {
  double sum = 0;
  for (const std::string& d : drones) {
    auto it = sample.containers.find(d);
    if (it == sample.containers.end()) return std::nullopt;
    sum += it->second.cpu_s;
  }
  return sum;
}

// flying_cpu_per_drone and start_cpu_per_agent_s (swarm_figures.hpp): between the first sample at
// or after `start_s` holding every drone and the last one before the first stop.
void FlyingCpu(const std::vector<std::string>& events, const CgroupSamples& samples,
               const std::vector<std::string>& drones, double start_s, std::optional<double> first_stop,
               SwarmFigures* f) {
  const CgroupSnapshot* first = nullptr;
  const CgroupSnapshot* last = nullptr;
  for (const CgroupSnapshot& s : samples) {
    if (s.wall_s < start_s || (first_stop && s.wall_s > *first_stop) || !AgentCpuAt(s, drones)) continue;
    if (first == nullptr) first = &s;
    last = &s;
  }
  if (first == nullptr || drones.empty()) return;
  const double cpu_first = *AgentCpuAt(*first, drones);
  f->start_cpu_per_agent_s = cpu_first / static_cast<double>(drones.size());
  const double sim_span_s = SimTimeBy(events, last->wall_s) - SimTimeBy(events, first->wall_s);
  if (last == first || sim_span_s <= 0) return;
  const double agents = static_cast<double>(drones.size());
  f->flying_cpu_per_drone = (*AgentCpuAt(*last, drones) - cpu_first) / (agents * sim_span_s);
}

}  // namespace

TrialSummary ParseResultJson(std::string_view json) {
  TrialSummary s;
  auto doc = yaml::Parse(json, "result.json");
  if (!doc || !doc->is_mapping()) return s;
  s.outcome = Text(doc->Find("outcome"));
  s.ending_line = Text(doc->Find("ending_line"));
  s.wall_s = Number(doc->Find("wall_s")).value_or(0);
  s.sim_s = Number(doc->Find("sim_s")).value_or(0);
  if (const yaml::Node* p = doc->Find("provenance"); p != nullptr && p->is_mapping()) {
    s.rtf_achieved = Number(p->Find("rtf_achieved"));
  }
  if (const yaml::Node* m = doc->Find("metrics"); m != nullptr && m->is_mapping()) {
    s.mission_time_s = Number(m->Find("mission_time_s"));
  }
  if (const yaml::Node* c = doc->Find("components"); c != nullptr && c->is_sequence()) {
    for (const yaml::Node& item : c->items()) {
      const std::string name = Text(item.Find("name"));
      if (name == "physics" || !item.is_mapping()) continue;
      const bool oom = Text(item.Find("oom_killed")) == "true";
      const double code = Number(item.Find("exit_code")).value_or(0);
      if (oom || code != 0) ++s.failed_agents;
    }
  }
  return s;
}

SwarmFigures ComputeSwarmFigures(const TrialSummary& result, const std::vector<std::string>& events,
                                 const CgroupSamples& samples, const std::vector<std::string>& drones) {
  SwarmFigures f;
  f.drones = static_cast<int>(drones.size());
  f.rtf = result.rtf_achieved;
  f.outcome = result.outcome;
  f.sim_s = result.sim_s;
  f.wall_s = result.wall_s;
  f.mission_complete = result.outcome == "success" && result.ending_line.find("event=mission_complete") != std::string::npos;
  if (f.mission_complete) f.mission_s = result.mission_time_s;

  int clock_lost = 0;
  double channel_sent = 0, channel_t = 0;
  std::optional<double> first_stop;
  for (const std::string& line : events) {
    auto doc = yaml::Parse(line, "events.jsonl");
    if (!doc || !doc->is_mapping()) continue;
    const std::string component = Text(doc->Find("component"));
    const std::string event = Text(doc->Find("event"));
    const double wall = Number(doc->Find("wall_s")).value_or(0);
    const std::optional<double> t = Number(doc->Find("t"));
    if (!f.start_s && t && *t > 0) f.start_s = wall;
    if (component == "orchestrator" && event == "stop" && !first_stop) first_stop = wall;
    if (component == "physics" && event == "clock") clock_lost = static_cast<int>(Number(doc->Find("lost")).value_or(0));
    if (component == "physics" && event == "channel" && t) {
      channel_sent = Number(doc->Find("sent")).value_or(0);
      channel_t = *t;
    }
    if (event == "ready" && component != "physics" && component != "orchestrator" &&
        std::find(drones.begin(), drones.end(), component) != drones.end()) {
      ++f.joined;
    }
  }
  f.lost = std::max(clock_lost, result.failed_agents);
  if (first_stop) f.exit_s = std::max(0.0, result.wall_s - *first_stop);
  if (channel_t > 0 && f.drones > 0) f.msgs_per_drone_s = channel_sent / channel_t / f.drones;

  // CPU: each container's last cumulative figure; memory: each one's peak, and the largest total.
  std::map<std::string, CgroupSample> last;
  for (const CgroupSnapshot& sample : samples) {
    double total = 0;
    for (const auto& [name, s] : sample.containers) {
      CgroupSample& l = last[name];
      l.cpu_s = std::max(l.cpu_s, s.cpu_s);
      l.mem_peak_mib = std::max({l.mem_peak_mib, s.mem_peak_mib, s.mem_mib});
      total += s.mem_mib;
    }
    f.mem_total_mib = std::max(f.mem_total_mib, total);
  }
  double agent_cpu = 0, agent_mem = 0;
  int agents = 0;
  for (const auto& [name, s] : last) {
    if (name == "physics") {
      if (result.sim_s > 0) f.physics_cpu = s.cpu_s / result.sim_s;
      continue;
    }
    if (std::find(drones.begin(), drones.end(), name) == drones.end()) continue;
    agent_cpu += s.cpu_s;
    agent_mem += s.mem_peak_mib;
    f.mem_agent_max_mib = std::max(f.mem_agent_max_mib, s.mem_peak_mib);
    ++agents;
  }
  if (agents > 0) f.mem_per_agent_mib = agent_mem / agents;
  if (f.drones > 0 && result.sim_s > 0) f.cpu_per_drone = agent_cpu / (f.drones * result.sim_s);
  if (f.start_s) FlyingCpu(events, samples, drones, *f.start_s, first_stop, &f);
  return f;
}

std::string FormatSwarmLine(const SwarmFigures& f, int scouts) {
  std::string line = "drones=" + std::to_string(scouts) + " agents=" + std::to_string(f.drones);
  line += " rtf=" + Fixed(f.rtf, 2);
  line += " cpu_per_drone=" + Fixed(f.cpu_per_drone, 4);
  line += " mem_per_agent_mib=" + Fixed(f.mem_per_agent_mib, 1);
  line += " mission_complete=" + std::string(f.mission_complete ? "1" : "0");
  line += " mission_s=" + Fixed(f.mission_s, 1);
  line += " msgs_per_drone_s=" + Fixed(f.msgs_per_drone_s, 1);
  line += " lost=" + std::to_string(f.lost);
  line += " start_s=" + Fixed(f.start_s, 1);
  line += " exit_s=" + Fixed(f.exit_s, 1);
  line += " joined=" + std::to_string(f.joined);
  line += " physics_cpu=" + Fixed(f.physics_cpu, 3);
  line += " flying_cpu_per_drone=" + Fixed(f.flying_cpu_per_drone, 4);
  line += " start_cpu_per_agent_s=" + Fixed(f.start_cpu_per_agent_s, 2);
  line += " mem_agent_max_mib=" + Fixed(f.mem_agent_max_mib, 1);
  line += " mem_total_mib=" + Fixed(f.mem_total_mib, 0);
  line += " sim_s=" + Fixed(f.sim_s, 1);
  line += " wall_s=" + Fixed(f.wall_s, 1);
  line += " outcome=" + (f.outcome.empty() ? std::string("-") : f.outcome);
  return line;
}

}  // namespace swarmbox::swarm
