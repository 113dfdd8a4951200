// NetemSpec: a radio impairment with tc netem semantics, and the trial-wide `network.mesh` block.
//
// One spec says what the link should look like; the injector picks how (kernel sch_netem, or the
// userspace mechanism where the kernel has none: see mechanism.hpp and radio_plan.hpp). Keys, as
// written in trial files (probabilities are fractions in [0, 1], not percent):
//
//   network:
//     mesh: {delay_ms: 100, jitter_ms: 20, distribution: normal, correlation: 0.25, loss: 0.05,
//            rate_kbit: 2000}
//   faults:
//     - at: 30s
//       duration: 20s
//       radio: {target: scout_1, loss: 0.3, to: [scout_2]}        # only the link to scout_2
//     - at: 60s
//       radio:
//         target: all
//         rules:                                                   # per-destination rules
//           - {to: [scout_2], delay_ms: 300}
//           - {to: [lifter], gilbert_elliott: {p: 0.05, r: 0.5, loss_bad: 1.0, loss_good: 0.0}}
//
//   delay_ms, jitter_ms      >= 0 [ms]
//   distribution             uniform (default) | normal | pareto | paretonormal; needs jitter_ms > 0
//   correlation              delay correlation, [0, 1] (netem's "delay D J C%")
//   loss, loss_correlation   random loss; or gilbert_elliott {p, r, loss_bad, loss_good} (netem
//                            "loss gemodel p r 1-h 1-k"), not both
//   duplicate, corrupt       [0, 1]
//   reorder, reorder_correlation, reorder_gap
//                            the fraction sent at once while the rest waits; needs delay_ms > 0
//   rate_kbit                > 0 [kbit/s, 1000 bit/s]
//   limit                    netem queue length [packets]; default: raised from delay x rate
//   to                       peer drone names: impair only the traffic to (kernel) / between
//                            (userspace) these peers; absent = all mesh traffic
//
// Validation here refuses what NO mechanism can do (unknown distribution, out-of-range values,
// distribution without jitter, reorder without delay); CheckMechanismSupports() in mechanism.hpp
// refuses what the chosen mechanism cannot do. Errors are kInvalidArgument at file:line:col.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::faults {

enum class DelayDistribution { kUniform, kNormal, kPareto, kParetoNormal };

std::string_view DistributionName(DelayDistribution distribution);
std::optional<DelayDistribution> DistributionFromName(std::string_view name);

// netem's Gilbert-Elliott model: two states, good and bad.
struct GilbertElliott {
  double p = 0.0;          // P(good -> bad) per packet
  double r = 1.0;          // P(bad -> good) per packet
  double loss_bad = 1.0;   // loss probability in the bad state (netem's 1-h)
  double loss_good = 0.0;  // loss probability in the good state (netem's 1-k)
  bool operator==(const GilbertElliott&) const = default;
};

struct NetemSpec {
  double delay_ms = 0.0;
  double jitter_ms = 0.0;
  DelayDistribution distribution = DelayDistribution::kUniform;
  double correlation = 0.0;  // delay correlation
  double loss = 0.0;
  double loss_correlation = 0.0;
  std::optional<GilbertElliott> gilbert_elliott;
  double duplicate = 0.0;
  double corrupt = 0.0;
  double reorder = 0.0;
  double reorder_correlation = 0.0;
  std::uint32_t reorder_gap = 0;  // 0 = netem's default (1: any packet may go early)
  std::optional<double> rate_kbit;
  std::optional<std::uint32_t> limit_packets;

  bool has_delay() const { return delay_ms > 0.0 || jitter_ms > 0.0; }
  bool has_loss() const { return loss > 0.0 || gilbert_elliott.has_value(); }
  // True when the spec changes nothing (then no qdisc or rule is installed).
  bool IsNoop() const;
  bool operator==(const NetemSpec&) const = default;
};

struct RadioRule {
  NetemSpec spec;
  std::vector<std::string> to;  // peer drone names; empty = all traffic on the mesh interface
  yaml::Mark mark;              // where the rule was written (messages)
  bool operator==(const RadioRule& o) const { return spec == o.spec && to == o.to; }
};

// The keys above except `to`, read into *spec through `reader` (which then knows them). Call
// ValidateNetemSpec() after reader.Finish().
void ReadNetemKeys(yaml::MapReader& reader, NetemSpec* spec);
// Refuses what no mechanism can do; `node` is the mapping the keys came from (for marks).
Status ValidateNetemSpec(const NetemSpec& spec, const yaml::Node& node);

// A mapping of netem keys plus optional `to`, or (allow_rules) a mapping holding `rules: [...]` of
// such mappings. `extra_keys` are accepted and ignored (e.g. "target" when the caller reads it).
Result<std::vector<RadioRule>> ParseRadioRules(const yaml::Node& node, std::string_view what,
                                               const std::vector<std::string>& extra_keys = {});

// Per-destination rules against the trial's drones: every `to` name is a drone other than the
// targets', no peer in two rules, at most one all-traffic rule.
Status ValidateRadioPeers(const std::vector<RadioRule>& rules, const std::vector<std::string>& drones);

// The `network.mesh` block: the radio of every agent from the start. A null/absent node gives no
// rules.
struct MeshImpairment {
  std::vector<RadioRule> rules;
  bool empty() const { return rules.empty(); }
};
Result<MeshImpairment> ParseMeshBlock(const yaml::Node& mesh);

}  // namespace swarmbox::faults
