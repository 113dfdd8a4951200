#include "swarmbox/faults/netem_spec.hpp"

#include <algorithm>
#include <set>
#include <string>
#include <utility>

namespace swarmbox::faults {
namespace {

Error Invalid(std::string message, const yaml::Node& node, std::string_view key) {
  const yaml::Node* child = node.is_mapping() ? node.Find(key) : nullptr;
  return Error(ErrorCode::kInvalidArgument, std::move(message),
               (child != nullptr ? *child : node).Where());
}

Status CheckFraction(double value, const yaml::Node& node, std::string_view key) {
  if (!(value >= 0.0 && value <= 1.0)) {
    return Invalid("'" + std::string(key) + "' is a probability in [0, 1] (a fraction, not percent), got " +
                       std::to_string(value),
                   node, key);
  }
  return Ok{};
}

// Decodes a distribution name (kept as a string until validation so the message can list names).
struct DistributionText {
  std::string name;
};

Status Decode(const yaml::Node& node, DistributionText* out) {
  return yaml::Decode(node, &out->name);
}

Status DecodeGilbertElliott(const yaml::Node& node, GilbertElliott* out) {
  yaml::MapReader r(node, "gilbert_elliott");
  r.Required("p", &out->p).Required("r", &out->r).Optional("loss_bad", &out->loss_bad)
      .Optional("loss_good", &out->loss_good);
  SWARMBOX_TRY(r.Finish());
  SWARMBOX_TRY(CheckFraction(out->p, node, "p"));
  SWARMBOX_TRY(CheckFraction(out->r, node, "r"));
  SWARMBOX_TRY(CheckFraction(out->loss_bad, node, "loss_bad"));
  SWARMBOX_TRY(CheckFraction(out->loss_good, node, "loss_good"));
  return Ok{};
}

}  // namespace

std::string_view DistributionName(DelayDistribution distribution) {
  switch (distribution) {
    case DelayDistribution::kUniform: return "uniform";
    case DelayDistribution::kNormal: return "normal";
    case DelayDistribution::kPareto: return "pareto";
    case DelayDistribution::kParetoNormal: return "paretonormal";
  }
  return "uniform";
}

std::optional<DelayDistribution> DistributionFromName(std::string_view name) {
  for (auto d : {DelayDistribution::kUniform, DelayDistribution::kNormal, DelayDistribution::kPareto,
                 DelayDistribution::kParetoNormal}) {
    if (DistributionName(d) == name) return d;
  }
  return std::nullopt;
}

bool NetemSpec::IsNoop() const {
  return !has_delay() && !has_loss() && duplicate == 0.0 && corrupt == 0.0 && reorder == 0.0 &&
         !rate_kbit.has_value();
}

// The distribution and gilbert_elliott keys need more than a plain Decode; the reader is told they
// exist through Child() and the values are read by ReadNetemExtras() below.
void ReadNetemKeys(yaml::MapReader& reader, NetemSpec* spec) {
  reader.Optional("delay_ms", &spec->delay_ms)
      .Optional("jitter_ms", &spec->jitter_ms)
      .Optional("correlation", &spec->correlation)
      .Optional("loss", &spec->loss)
      .Optional("loss_correlation", &spec->loss_correlation)
      .Optional("duplicate", &spec->duplicate)
      .Optional("corrupt", &spec->corrupt)
      .Optional("reorder", &spec->reorder)
      .Optional("reorder_correlation", &spec->reorder_correlation)
      .Optional("reorder_gap", &spec->reorder_gap)
      .Optional("rate_kbit", &spec->rate_kbit)
      .Optional("limit", &spec->limit_packets);
  if (const yaml::Node* d = reader.Child("distribution")) {
    DistributionText text;
    if (auto s = Decode(*d, &text); !s) {
      reader.Fail(s.error());
    } else if (auto dist = DistributionFromName(text.name)) {
      spec->distribution = *dist;
    } else {
      reader.Fail(Error(ErrorCode::kInvalidArgument,
                        "distribution '" + text.name +
                            "' is supported by neither mechanism (kernel netem nor the userspace "
                            "delayer); use uniform, normal, pareto or paretonormal",
                        d->Where()));
    }
  }
  if (const yaml::Node* ge = reader.Child("gilbert_elliott")) {
    GilbertElliott model;
    if (auto s = DecodeGilbertElliott(*ge, &model); !s) {
      reader.Fail(s.error());
    } else {
      spec->gilbert_elliott = model;
    }
  }
}

namespace {

constexpr double kMaxDelayMs = 600000.0;           // ten minutes
constexpr std::uint32_t kMaxReorderGap = 1000000;  // packets

// The probabilities of a spec, each with its YAML key, in the order they are checked.
constexpr std::pair<double NetemSpec::*, std::string_view> kFractionKeys[] = {
    {&NetemSpec::correlation, "correlation"},
    {&NetemSpec::loss, "loss"},
    {&NetemSpec::loss_correlation, "loss_correlation"},
    {&NetemSpec::duplicate, "duplicate"},
    {&NetemSpec::corrupt, "corrupt"},
    {&NetemSpec::reorder, "reorder"},
    {&NetemSpec::reorder_correlation, "reorder_correlation"},
};

// Delays non-negative and bounded, probabilities in [0, 1].
Status CheckValueRanges(const NetemSpec& spec, const yaml::Node& node) {
  if (!(spec.delay_ms >= 0.0)) return Invalid("'delay_ms' must be >= 0", node, "delay_ms");
  if (!(spec.jitter_ms >= 0.0)) return Invalid("'jitter_ms' must be >= 0", node, "jitter_ms");
  if (spec.delay_ms > kMaxDelayMs) return Invalid("'delay_ms' above 10 minutes", node, "delay_ms");
  for (const auto& [field, key] : kFractionKeys) SWARMBOX_TRY(CheckFraction(spec.*field, node, key));
  return Ok{};
}

// Keys that only mean something together with another (jitter shapes, correlations, reordering).
Status CheckKeyCombinations(const NetemSpec& spec, const yaml::Node& node) {
  if (spec.distribution != DelayDistribution::kUniform && spec.jitter_ms <= 0.0) {
    return Invalid("distribution '" + std::string(DistributionName(spec.distribution)) +
                       "' needs jitter_ms > 0 (it shapes the jitter around delay_ms)",
                   node, "distribution");
  }
  if (spec.correlation > 0.0 && spec.jitter_ms <= 0.0) {
    return Invalid("'correlation' correlates the jitter and needs jitter_ms > 0", node, "correlation");
  }
  if (spec.gilbert_elliott && (spec.loss > 0.0 || spec.loss_correlation > 0.0)) {
    return Invalid("give either 'loss' (random) or 'gilbert_elliott', not both", node, "gilbert_elliott");
  }
  if (spec.loss_correlation > 0.0 && spec.loss <= 0.0) {
    return Invalid("'loss_correlation' needs loss > 0", node, "loss_correlation");
  }
  if (spec.reorder > 0.0 && spec.delay_ms <= 0.0) {
    return Invalid("'reorder' needs delay_ms > 0: the reordered fraction is sent at once while the "
                   "rest waits delay_ms",
                   node, "reorder");
  }
  if ((spec.reorder_correlation > 0.0 || spec.reorder_gap > 0) && spec.reorder <= 0.0) {
    return Invalid("'reorder_correlation' and 'reorder_gap' need reorder > 0", node,
                   spec.reorder_gap > 0 ? "reorder_gap" : "reorder_correlation");
  }
  return Ok{};
}

}  // namespace

Status ValidateNetemSpec(const NetemSpec& spec, const yaml::Node& node) {
  SWARMBOX_TRY(CheckValueRanges(spec, node));
  SWARMBOX_TRY(CheckKeyCombinations(spec, node));
  if (spec.reorder_gap > kMaxReorderGap) {
    return Invalid("'reorder_gap' above 1,000,000 packets", node, "reorder_gap");
  }
  if (spec.rate_kbit && !(*spec.rate_kbit > 0.0)) {
    return Invalid("'rate_kbit' must be > 0 [kbit/s]", node, "rate_kbit");
  }
  if (spec.limit_packets && *spec.limit_packets == 0) {
    return Invalid("'limit' must be at least 1 packet", node, "limit");
  }
  return Ok{};
}

namespace {

Result<RadioRule> ParseOneRule(const yaml::Node& node, std::string_view what,
                               const std::vector<std::string>& extra_keys, bool allow_noop) {
  const bool allow_to = true;
  RadioRule rule;
  rule.mark = node.mark();
  yaml::MapReader r(node, std::string(what));
  ReadNetemKeys(r, &rule.spec);
  if (allow_to) r.Optional("to", &rule.to);
  for (const auto& key : extra_keys) r.Child(key);
  SWARMBOX_TRY(r.Finish());
  SWARMBOX_TRY(ValidateNetemSpec(rule.spec, node));
  if (allow_to && node.Find("to") != nullptr && rule.to.empty()) {
    return Invalid("'to' lists peer drone names; an empty list impairs nothing", node, "to");
  }
  if (rule.spec.IsNoop() && !allow_noop) {
    return Error(ErrorCode::kInvalidArgument,
                 std::string(what) + " impairs nothing: give at least one of delay_ms, jitter_ms, "
                                     "loss, gilbert_elliott, duplicate, corrupt, reorder, rate_kbit",
                 node.Where());
  }
  return rule;
}

// allow_noop: rules that impair nothing are dropped instead of refused (network.mesh after
// `--set network.mesh.loss=0`).
Result<std::vector<RadioRule>> ParseRules(const yaml::Node& node, std::string_view what,
                                          const std::vector<std::string>& extra_keys, bool allow_noop) {
  if (!node.is_mapping()) {
    return Error(ErrorCode::kInvalidArgument,
                 "expected " + std::string(what) + " to be a mapping of netem keys (delay_ms, loss, ...)",
                 node.Where());
  }
  std::vector<RadioRule> rules;
  if (const yaml::Node* list = node.Find("rules")) {
    yaml::MapReader r(node, std::string(what));
    r.Child("rules");
    for (const auto& key : extra_keys) r.Child(key);
    SWARMBOX_TRY(r.Finish());
    if (!list->is_sequence() || list->items().empty()) {
      return Error(ErrorCode::kInvalidArgument,
                   "'rules' is a non-empty list of {to: [...], <netem keys>}", list->Where());
    }
    for (const yaml::Node& item : list->items()) {
      auto rule = ParseOneRule(item, std::string(what) + " rule", {}, allow_noop);
      if (!rule) return rule.error();
      if (!rule->spec.IsNoop()) rules.push_back(std::move(*rule));
    }
    return rules;
  }
  auto rule = ParseOneRule(node, what, extra_keys, allow_noop);
  if (!rule) return rule.error();
  if (!rule->spec.IsNoop()) rules.push_back(std::move(*rule));
  return rules;
}

}  // namespace

Result<std::vector<RadioRule>> ParseRadioRules(const yaml::Node& node, std::string_view what,
                                               const std::vector<std::string>& extra_keys) {
  return ParseRules(node, what, extra_keys, /*allow_noop=*/false);
}

Status ValidateRadioPeers(const std::vector<RadioRule>& rules, const std::vector<std::string>& drones) {
  std::set<std::string> seen;
  int all_traffic = 0;
  for (const RadioRule& rule : rules) {
    const std::string where = rule.mark.ToString();
    if (rule.to.empty()) {
      if (++all_traffic > 1) {
        return Error(ErrorCode::kInvalidArgument,
                     "two rules without 'to': at most one rule may cover all traffic", where);
      }
      continue;
    }
    for (const std::string& peer : rule.to) {
      if (std::find(drones.begin(), drones.end(), peer) == drones.end()) {
        std::string known;
        for (const auto& d : drones) known += (known.empty() ? "" : ", ") + d;
        return Error(ErrorCode::kInvalidArgument,
                     "per-destination rule names unknown peer '" + peer + "' (drones: " + known + ")",
                     where);
      }
      if (!seen.insert(peer).second) {
        return Error(ErrorCode::kInvalidArgument,
                     "peer '" + peer + "' appears in two per-destination rules", where);
      }
    }
  }
  return Ok{};
}

Result<MeshImpairment> ParseMeshBlock(const yaml::Node& mesh) {
  MeshImpairment out;
  if (mesh.is_null() || yaml::IsNullScalar(mesh)) return out;
  auto rules = ParseRules(mesh, "network.mesh", {}, /*allow_noop=*/true);
  if (!rules) return rules.error();
  out.rules = std::move(*rules);
  return out;
}

}  // namespace swarmbox::faults
