#include "swarmbox/faults/fault_event.hpp"

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/faults/detail/number_format.hpp"
#include "swarmbox/faults/duration_ms.hpp"

namespace swarmbox::faults {
namespace {

std::string List(const std::vector<std::string>& names) {
  std::string out = "[";
  for (std::size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + names[i];
  return out + "]";
}

void Kv(std::string* out, std::string_view key, const std::string& value) {
  if (!out->empty()) *out += ' ';
  *out += std::string(key) + "=" + value;
}

std::string Num(double v) { return detail::FormatDecimal(v, 6); }

}  // namespace

std::string_view FaultPhaseName(FaultPhase phase) {
  switch (phase) {
    case FaultPhase::kRequested: return "requested";
    case FaultPhase::kApplied: return "applied";
    case FaultPhase::kRemoveRequested: return "remove_requested";
    case FaultPhase::kRemoved: return "removed";
    case FaultPhase::kFailed: return "failed";
  }
  return "failed";
}

std::string DescribeRule(const RadioRule& rule) {
  const NetemSpec& s = rule.spec;
  std::string out;
  if (s.delay_ms > 0) Kv(&out, "delay_ms", Num(s.delay_ms));
  if (s.jitter_ms > 0) Kv(&out, "jitter_ms", Num(s.jitter_ms));
  if (s.distribution != DelayDistribution::kUniform) {
    Kv(&out, "distribution", std::string(DistributionName(s.distribution)));
  }
  if (s.correlation > 0) Kv(&out, "correlation", Num(s.correlation));
  if (s.loss > 0) Kv(&out, "loss", Num(s.loss));
  if (s.loss_correlation > 0) Kv(&out, "loss_correlation", Num(s.loss_correlation));
  if (s.gilbert_elliott) {
    const auto& g = *s.gilbert_elliott;
    Kv(&out, "gilbert_elliott", "{p: " + Num(g.p) + ", r: " + Num(g.r) + ", loss_bad: " + Num(g.loss_bad) +
                                    ", loss_good: " + Num(g.loss_good) + "}");
  }
  if (s.duplicate > 0) Kv(&out, "duplicate", Num(s.duplicate));
  if (s.corrupt > 0) Kv(&out, "corrupt", Num(s.corrupt));
  if (s.reorder > 0) Kv(&out, "reorder", Num(s.reorder));
  if (s.reorder_correlation > 0) Kv(&out, "reorder_correlation", Num(s.reorder_correlation));
  if (s.reorder_gap > 0) Kv(&out, "reorder_gap", std::to_string(s.reorder_gap));
  if (s.rate_kbit) Kv(&out, "rate_kbit", Num(*s.rate_kbit));
  if (s.limit_packets) Kv(&out, "limit", std::to_string(*s.limit_packets));
  if (!rule.to.empty()) Kv(&out, "to", List(rule.to));
  return out;
}

std::string DescribeFault(const Fault& fault) {
  struct Visitor {
    std::string operator()(const RadioFault& r) const {
      std::string out;
      for (std::size_t i = 0; i < r.rules.size(); ++i) out += (i ? "; " : "") + DescribeRule(r.rules[i]);
      return out;
    }
    std::string operator()(const PartitionFault& p) const {
      std::string groups = "[";
      for (std::size_t i = 0; i < p.groups.size(); ++i) groups += (i ? ", " : "") + List(p.groups[i]);
      return "groups=" + groups + "] oneway=" + (p.oneway ? "true" : "false");
    }
    std::string operator()(const ProcessFault& p) const {
      if (p.action == ProcessAction::kKill) return "signal=" + p.signal;
      if (p.action == ProcessAction::kPause) return "";
      return "timeout_s=" + std::to_string(p.timeout_s);
    }
    std::string operator()(const GpsDropout&) const { return ""; }
    std::string operator()(const GpsDegrade& g) const {
      return "h_acc_m=" + Num(g.h_acc_m) + " v_acc_m=" + Num(g.v_acc_m);
    }
    std::string operator()(const ImuBias& b) const {
      auto v = [](const std::array<double, 3>& a) { return "[" + Num(a[0]) + ", " + Num(a[1]) + ", " + Num(a[2]) + "]"; };
      return "accel_m_s2=" + v(b.accel_m_s2) + " gyro_rad_s=" + v(b.gyro_rad_s);
    }
    std::string operator()(const WindGust& w) const {
      return "speed_m_s=" + Num(w.speed_m_s) + " direction_deg=" + Num(w.direction_deg) +
             " vertical_m_s=" + Num(w.vertical_m_s);
    }
  };
  std::string out = std::visit(Visitor{}, fault.action);
  if (fault.duration_ms) out += std::string(out.empty() ? "" : " ") + "duration=" + FormatDurationMs(*fault.duration_ms);
  return out;
}

std::string FaultEventJson(const Fault& fault, const FaultEventRecord& record) {
  using yaml::Node;
  Node root = Node::Mapping();
  auto str = [](std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); };
  root.Set("type", str("fault"));
  root.Set("phase", str(FaultPhaseName(record.phase)));
  root.Set("fault", str(fault.id));
  root.Set("kind", str(fault.kind()));
  root.Set("start", str(fault.start.ToString()));
  root.Set("t_sim_s", Node::Scalar(detail::FormatDecimal(record.t_sim_s, 3)));
  root.Set("wall_s", Node::Scalar(detail::FormatDecimal(record.wall_s, 3)));
  Node targets = Node::Sequence();
  for (const auto& t : record.targets) targets.Append(str(t));
  root.Set("targets", std::move(targets));
  root.Set("mechanism", str(record.mechanism));
  root.Set("spec", str(DescribeFault(fault)));
  if (record.phase == FaultPhase::kFailed) root.Set("error", str(record.error));
  if (!record.note.empty()) root.Set("note", str(record.note));
  if (record.requested_t_sim_s) {
    root.Set("requested_t_sim_s", Node::Scalar(detail::FormatDecimal(*record.requested_t_sim_s, 3)));
  }
  if (record.requested_wall_s) {
    root.Set("requested_wall_s", Node::Scalar(detail::FormatDecimal(*record.requested_wall_s, 3)));
  }
  return yaml::EmitJson(root);
}

}  // namespace swarmbox::faults

namespace swarmbox::faults {

std::string MeshEventJson(const std::string& node, const std::vector<RadioRule>& rules,
                          const FaultEventRecord& record) {
  using yaml::Node;
  auto str = [](std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); };
  std::string spec;
  for (std::size_t i = 0; i < rules.size(); ++i) spec += (i ? "; " : "") + DescribeRule(rules[i]);
  Node root = Node::Mapping();
  root.Set("type", str("mesh"));
  root.Set("phase", str(FaultPhaseName(record.phase)));
  root.Set("node", str(node));
  root.Set("t_sim_s", Node::Scalar(detail::FormatDecimal(record.t_sim_s, 3)));
  root.Set("wall_s", Node::Scalar(detail::FormatDecimal(record.wall_s, 3)));
  root.Set("mechanism", str(record.mechanism));
  root.Set("spec", str(spec));
  if (record.phase == FaultPhase::kFailed) root.Set("error", str(record.error));
  if (!record.note.empty()) root.Set("note", str(record.note));
  return yaml::EmitJson(root);
}

}  // namespace swarmbox::faults
