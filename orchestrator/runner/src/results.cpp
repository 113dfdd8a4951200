#include "swarmbox/runner/results.hpp"

#include <charconv>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/report/results_csv.hpp"

namespace swarmbox::runner {

namespace {

using yaml::Node;

std::string Num(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, 3);
  std::string s(buf, r.ptr);
  while (s.size() > 1 && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

Node Str(std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); }
Node Bare(std::string s) { return Node::Scalar(std::move(s)); }

// A logfmt value as JSON: numbers bare, everything else a string.
Node Value(const std::string& v) {
  if (!v.empty() && yaml::ScalarAsDouble(v).has_value() && v.find_first_of("xXoO_") == std::string::npos &&
      v.find("inf") == std::string::npos && v.find("nan") == std::string::npos && v[0] != '.' && v[0] != '+') {
    return Bare(v);
  }
  return Str(v);
}

Node RadioNode(const TrialResult& r) {
  Node radio = Node::Mapping();
  radio.Set("model", Str(r.radio_model));
  radio.Set("profile", r.radio_profile.empty() ? Node::Null() : Str(r.radio_profile));
  return radio;
}

// Every metric of report::MetricNames, in its order: null where the trial has no value.
Node MetricsNode(const TrialResult& r) {
  Node metrics = Node::Mapping();
  for (const std::string& name : report::MetricNames()) {
    auto it = r.metrics.find(name);
    metrics.Set(name, it != r.metrics.end() && it->second ? Bare(report::CsvNumber(*it->second))
                                                           : Node::Null());
  }
  return metrics;
}

Node ComponentsNode(const std::vector<ComponentReport>& components) {
  Node sequence = Node::Sequence();
  for (const ComponentReport& c : components) {
    Node cn = Node::Mapping();
    cn.Set("name", Str(c.name));
    cn.Set("exit_code", c.exit_code ? Bare(std::to_string(*c.exit_code)) : Node::Null());
    cn.Set("oom_killed", Bare(c.oom_killed ? "true" : "false"));
    cn.Set("log", Str(c.log_file));
    cn.Set("log_lines", Bare(std::to_string(c.log_lines)));
    sequence.Append(std::move(cn));
  }
  return sequence;
}

// The containers killed for going over their memory limit (`limits:`), at a glance.
Node OomKilledNode(const std::vector<ComponentReport>& components) {
  Node oom_killed = Node::Sequence();
  for (const ComponentReport& c : components) {
    if (c.oom_killed) oom_killed.Append(Str(c.name));
  }
  return oom_killed;
}

Node StringsNode(const std::vector<std::string>& strings) {
  Node sequence = Node::Sequence();
  for (const std::string& s : strings) sequence.Append(Str(s));
  return sequence;
}

Node TimingNode(const TrialTiming& t) {
  Node timing = Node::Mapping();
  auto seconds = [&](const std::optional<double>& v) { return v ? Bare(Num(*v)) : Node::Null(); };
  timing.Set("containers", Bare(std::to_string(t.containers)));
  timing.Set("created_s", seconds(t.created_s));
  timing.Set("started_s", seconds(t.started_s));
  timing.Set("joined_s", seconds(t.joined_s));
  timing.Set("teardown_s", seconds(t.teardown_s));
  return timing;
}

}  // namespace

std::string ResultJson(const TrialResult& r) {
  Node doc = Node::Mapping();
  doc.Set("trial", Str(r.trial));
  doc.Set("outcome", Str(dsl::OutcomeName(r.verdict.outcome)));
  doc.Set("reason", Str(r.verdict.reason));
  doc.Set("wall_s", Bare(Num(r.wall_s)));
  doc.Set("sim_s", Bare(Num(r.sim_s)));
  doc.Set("seed", Bare(std::to_string(r.seed)));
  doc.Set("host", Str(r.host));
  if (!r.radio_model.empty()) doc.Set("radio", RadioNode(r));
  doc.Set("metrics", MetricsNode(r));
  doc.Set("trial_id", Str(r.trial_id));
  doc.Set("run_id", Str(r.run_id));
  doc.Set("source", Str(r.verdict.source));
  doc.Set("ending_line", Str(r.ending_line));
  doc.Set("restarts", Bare(std::to_string(r.restarts)));
  doc.Set("components", ComponentsNode(r.components));
  doc.Set("oom_killed", OomKilledNode(r.components));
  doc.Set("problems", StringsNode(r.problems));
  doc.Set("timing", TimingNode(r.timing));
  doc.Set("provenance", report::ProvenanceNode(r.provenance));
  return yaml::EmitJson(doc) + "\n";
}

void RtfMeter::Observe(double wall_s, double sim_s) {
  if (!first_ && sim_s > 0) first_ = {wall_s, sim_s};
  last_ = {wall_s, sim_s};
}

std::optional<double> RtfMeter::Achieved() const {
  if (!first_) return std::nullopt;
  const double wall = last_.first - first_->first;
  const double sim = last_.second - first_->second;
  if (wall <= 0 || sim <= 0) return std::nullopt;
  return sim / wall;
}

std::optional<std::string> LogEventJson(double wall_s, std::string_view component,
                                        const LogfmtFields& fields) {
  if (!FindField(fields, "event")) return std::nullopt;
  Node doc = Node::Mapping();
  doc.Set("wall_s", Bare(Num(wall_s)));
  doc.Set("component", Str(component));
  for (const auto& [k, v] : fields) {
    if (k == "wall_s" || k == "component") continue;  // ours win
    doc.Set(k, Value(v));
  }
  return yaml::EmitJson(doc);
}

std::string LifecycleEventJson(double wall_s, std::string_view event, std::string_view target,
                               const dsl::Verdict& verdict) {
  Node doc = Node::Mapping();
  doc.Set("wall_s", Bare(Num(wall_s)));
  doc.Set("component", Str("orchestrator"));
  doc.Set("event", Str(event));
  doc.Set("target", Str(target));
  doc.Set("outcome", Str(dsl::OutcomeName(verdict.outcome)));
  if (!verdict.reason.empty()) doc.Set("reason", Str(verdict.reason));
  return yaml::EmitJson(doc);
}

int ExitCodeFor(const dsl::Verdict& verdict) {
  switch (verdict.outcome) {
    case dsl::Outcome::kSuccess: return 0;
    case dsl::Outcome::kTimeout:
    case dsl::Outcome::kFailure: return 1;
    case dsl::Outcome::kError: return 3;
  }
  return 3;
}

}  // namespace swarmbox::runner
