#include "guest_scenarios.hpp"

#include <cstdio>
#include <map>
#include <random>
#include <variant>

#include "guest_console.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/faults/fault_spec.hpp"
#include "swarmbox/faults/leader_tracker.hpp"
#include "swarmbox/faults/netem_spec.hpp"
#include "swarmbox/faults/partition_plan.hpp"
#include "swarmbox/faults/radio_layers.hpp"
#include "swarmbox/faults/radio_plan.hpp"
#include "swarmbox/faults/target_resolver.hpp"

namespace swarmbox::netem_guest {
namespace {

using faults::Mechanism;
using faults::RadioRule;
using faults::testing::ProbeSample;

constexpr Mechanism kKernel = Mechanism::kKernelNetem;

std::string Fixed(double value, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

Result<std::vector<RadioRule>> Mesh(std::string_view yaml_text) {
  auto node = yaml::Parse(yaml_text, "network.mesh");
  if (!node) return node.error();
  auto mesh = faults::ParseMeshBlock(*node);
  if (!mesh) return mesh.error();
  return mesh->rules;
}

Result<std::vector<faults::Fault>> Faults(std::string_view yaml_text,
                                          const std::vector<std::string>& drones) {
  auto node = yaml::Parse(yaml_text, "faults");
  if (!node) return node.error();
  auto list = faults::ParseFaults(*node);
  if (!list) return list.error();
  SWARMBOX_TRY(faults::ValidateFaults(*list, drones));
  return list;
}

// The radio half of FaultInjector (orchestrator/runner), on the lab's namespaces instead of the
// agents' sidecars: the network.mesh rules on every radio node, radio faults layered over them with
// RadioLayers, each change planned with PlanRadioChange from the rules installed before.
class RadioInjector {
 public:
  RadioInjector(GuestLab& lab, std::vector<RadioRule> mesh)
      : lab_(lab), layers_(std::move(mesh), lab.RadioNodes()) {}

  Status ApplyMesh() {
    for (const std::string& node : lab_.RadioNodes()) {
      const auto rules = layers_.Effective(node);
      installed_[node] = rules;
      auto plan = faults::PlanRadio(rules, lab_.Link(node), kKernel);
      if (!plan) return plan.error().Context("network.mesh on " + node);
      SWARMBOX_TRY(faults::RunCommands(lab_.In(node), plan->apply));
    }
    return Ok{};
  }

  Status Apply(const faults::Fault& fault) {
    const auto* radio = std::get_if<faults::RadioFault>(&fault.action);
    if (radio == nullptr)
      return Error(ErrorCode::kInvalidArgument, "fault " + fault.id + " is not a radio fault");
    auto targets = faults::ResolveTarget(radio->target, lab_.RadioNodes(), leaders_, rng_);
    if (!targets) return targets.error();
    const auto before = installed_;
    return Change(before, layers_.Push(fault.id, *targets, radio->rules));
  }

  Status Remove(const std::string& id) {
    const auto before = installed_;
    return Change(before, layers_.Pop(id));
  }

  // Every node's installed plan undone (the trial's end would leave it to the namespace's removal).
  Status Undo() {
    Status first = Ok{};
    for (const std::string& node : lab_.RadioNodes()) {
      auto plan = faults::PlanRadio(installed_[node], lab_.Link(node), kKernel);
      if (!plan) return plan.error();
      Status s = faults::RunAllCommands(lab_.In(node), plan->undo);
      if (!s && first) first = s;
      installed_[node].clear();
    }
    return first;
  }

  // The mesh plan of `node` applied once more over what is there (tc's `replace`).
  Status ReapplyMesh(const std::string& node) {
    auto plan = faults::PlanRadio(installed_[node], lab_.Link(node), kKernel);
    if (!plan) return plan.error();
    return faults::RunCommands(lab_.In(node), plan->apply);
  }

 private:
  Status Change(const std::map<std::string, std::vector<RadioRule>>& before,
                const std::vector<std::string>& changed) {
    for (const std::string& node : changed) {
      auto it = before.find(node);
      const std::vector<RadioRule> from = it == before.end() ? std::vector<RadioRule>{} : it->second;
      const auto to = layers_.Effective(node);
      auto plan = faults::PlanRadioChange(from, to, lab_.Link(node), kKernel);
      if (!plan) return plan.error().Context(node);
      SWARMBOX_TRY(faults::RunCommands(lab_.In(node), plan->apply));
      installed_[node] = to;
    }
    return Ok{};
  }

  GuestLab& lab_;
  faults::RadioLayers layers_;
  std::map<std::string, std::vector<RadioRule>> installed_;
  faults::LeaderTracker leaders_;
  std::mt19937_64 rng_{42};
};

void ReportSample(GuestLab& lab, const std::string& probe, const ProbeSample& sample,
                  const Fields& extra = {}) {
  Fields f = {{"scenario", lab.scenario()}, {"probe", probe}};
  for (auto& kv : SampleFields(sample)) f.push_back(std::move(kv));
  f.insert(f.end(), extra.begin(), extra.end());
  lab.reporter().Record(kEventMeasured, f);
}

// Measures a -> peer and reports it as `probe`.
Result<ProbeSample> Probe(GuestLab& lab, const std::string& probe, const std::string& peer, int count,
                          std::int64_t spacing_us, const Fields& extra = {}) {
  auto sample = lab.Measure(peer, count, spacing_us);
  if (!sample) return sample.error().Context("probe " + probe);
  ReportSample(lab, probe, *sample, extra);
  return sample;
}

Status ReportTree(GuestLab& lab, const std::string& node, const std::string& stage) {
  auto tree = lab.Tree(node);
  if (!tree) return tree.error();
  lab.reporter().Record(kEventTree,
                        {{"scenario", lab.scenario()}, {"drone", node}, {"stage", stage}, {"text", *tree}});
  return Ok{};
}

// A network.mesh block on every agent: measure a -> b, undo, measure again; trees before and after.
Status MeshScenario(GuestLab& lab, std::string_view mesh_yaml, int count, std::int64_t spacing_us) {
  auto mesh = Mesh(mesh_yaml);
  if (!mesh) return mesh.error();
  SWARMBOX_TRY(ReportTree(lab, "a", "pristine"));
  RadioInjector injector(lab, *mesh);
  SWARMBOX_TRY(injector.ApplyMesh());
  SWARMBOX_TRY(ReportTree(lab, "a", "applied"));
  auto impaired = Probe(lab, "impaired", "b", count, spacing_us);
  if (!impaired) return impaired.error();
  SWARMBOX_TRY(injector.Undo());
  SWARMBOX_TRY(ReportTree(lab, "a", "undone"));
  auto after = Probe(lab, "after_undo", "b", 300, 1000);
  if (!after) return after.error();
  return Ok{};
}

Status RunMesh(GuestLab& lab) {
  return MeshScenario(lab, "{delay_ms: 50, jitter_ms: 10, distribution: normal, loss: 0.05}", 3000, 1000);
}

Status RunFixed(GuestLab& lab) { return MeshScenario(lab, "{delay_ms: 50}", 1000, 2000); }

Status RunPerDestination(GuestLab& lab) {
  auto faults = Faults("[{at: 1s, name: to_c, radio: {target: a, to: [c], delay_ms: 80, rate_kbit: 2000}}]",
                       lab.Drones());
  if (!faults) return faults.error();
  RadioInjector injector(lab, {});
  SWARMBOX_TRY(ReportTree(lab, "a", "pristine"));
  SWARMBOX_TRY(injector.Apply(faults->front()));
  SWARMBOX_TRY(ReportTree(lab, "a", "applied"));
  if (auto s = Probe(lab, "to_b", "b", 300, 2000); !s) return s.error();
  if (auto s = Probe(lab, "to_c", "c", 300, 2000); !s) return s.error();
  // 1000-byte datagrams every 1 ms (8.3 Mbit/s offered) against the rule's 2000 kbit/s.
  constexpr std::size_t kPayload = 1000;
  auto rate = lab.Measure("c", 300, 1000, kPayload);
  if (!rate) return rate.error();
  const auto kbit = ArrivalRateKbit(*rate, kPayload + GuestLab::kHeaderBytes);
  ReportSample(lab, "rate_to_c", *rate,
               {{"payload_bytes", std::to_string(kPayload)}, {"wire_kbit", kbit ? Fixed(*kbit, 1) : "none"}});
  SWARMBOX_TRY(injector.Remove("to_c"));
  SWARMBOX_TRY(ReportTree(lab, "a", "removed"));
  if (auto s = Probe(lab, "after_removal", "c", 300, 2000); !s) return s.error();
  return Ok{};
}

Status RunRate(GuestLab& lab) {
  auto mesh = Mesh("{rate_kbit: 2000}");
  if (!mesh) return mesh.error();
  RadioInjector injector(lab, *mesh);
  SWARMBOX_TRY(injector.ApplyMesh());
  SWARMBOX_TRY(ReportTree(lab, "a", "applied"));
  constexpr std::size_t kPayload = 1000;
  auto rate = lab.Measure("b", 400, 1000, kPayload);
  if (!rate) return rate.error();
  const auto kbit = ArrivalRateKbit(*rate, kPayload + GuestLab::kHeaderBytes);
  ReportSample(lab, "rate", *rate,
               {{"payload_bytes", std::to_string(kPayload)}, {"wire_kbit", kbit ? Fixed(*kbit, 1) : "none"}});
  return injector.Undo();
}

Status RunReorder(GuestLab& lab) {
  auto faults =
      Faults("[{at: 1s, name: shuffle, radio: {target: a, delay_ms: 10, reorder: 0.25}}]", lab.Drones());
  if (!faults) return faults.error();
  RadioInjector injector(lab, {});
  SWARMBOX_TRY(injector.Apply(faults->front()));
  SWARMBOX_TRY(ReportTree(lab, "a", "applied"));
  auto s = lab.Measure("b", 3000, 1000);
  if (!s) return s.error();
  // Sent at once: no 10 ms delay (under 5 ms); overtaken: arrived after a higher number.
  ReportSample(
      lab, "impaired", *s,
      {{"early", Fixed(EarlyFraction(*s, 5.0), 5)}, {"out_of_order", Fixed(OutOfOrderFraction(*s), 5)}});
  return injector.Remove("shuffle");
}

Status RunDuplicate(GuestLab& lab) {
  auto mesh = Mesh("{delay_ms: 5, duplicate: 0.1}");
  if (!mesh) return mesh.error();
  SWARMBOX_TRY(ReportTree(lab, "a", "pristine"));
  RadioInjector injector(lab, *mesh);
  SWARMBOX_TRY(injector.ApplyMesh());
  if (auto s = Probe(lab, "impaired", "b", 3000, 1000); !s) return s.error();
  SWARMBOX_TRY(injector.Undo());
  SWARMBOX_TRY(ReportTree(lab, "a", "undone"));
  if (auto s = Probe(lab, "after_undo", "b", 300, 1000); !s) return s.error();
  return Ok{};
}

Status RunCorrupt(GuestLab& lab) {
  auto mesh = Mesh("{corrupt: 0.1}");
  if (!mesh) return mesh.error();
  RadioInjector injector(lab, *mesh);
  SWARMBOX_TRY(injector.ApplyMesh());
  auto errors_before = lab.ReceiveErrors("b");
  if (!errors_before) return errors_before.error();
  auto s = lab.Measure("b", 3000, 1000);
  if (!s) return s.error();
  auto errors_after = lab.ReceiveErrors("b");
  if (!errors_after) return errors_after.error();
  ReportSample(lab, "impaired", *s, {{"receive_errors", std::to_string(*errors_after - *errors_before)}});
  SWARMBOX_TRY(injector.Undo());
  if (auto after = Probe(lab, "after_undo", "b", 300, 1000); !after) return after.error();
  return Ok{};
}

Status RunGilbertElliott(GuestLab& lab) {
  auto faults = Faults(
      "[{at: 1s, name: fade, radio: {target: a, delay_ms: 5, gilbert_elliott: {p: 0.02, r: 0.25, loss_bad: "
      "1.0, "
      "loss_good: 0.0}}}]",
      lab.Drones());
  if (!faults) return faults.error();
  RadioInjector injector(lab, {});
  SWARMBOX_TRY(injector.Apply(faults->front()));
  auto s = lab.Measure("b", 3000, 1000);
  if (!s) return s.error();
  const LossBursts bursts = CountLossBursts(*s);
  ReportSample(lab, "impaired", *s,
               {{"bursts", std::to_string(bursts.bursts)}, {"mean_burst", Fixed(bursts.mean_length, 3)}});
  return injector.Remove("fade");
}

Status RunPartition(GuestLab& lab) {
  auto faults = Faults("[{at: 1s, name: cut, partition: {groups: [[a], [b]], oneway: true}}]", {"a", "b"});
  if (!faults) return faults.error();
  const auto& partition = std::get<faults::PartitionFault>(faults->front().action);
  auto plan = faults::PlanPartition(partition, lab.MeshNodes(), 3);
  if (!plan) return plan.error();
  if (plan->apply.count("a") != 0) return Error(ErrorCode::kInternal, "a one-way cut from a changes a");
  SWARMBOX_TRY(faults::RunCommands(lab.In("b"), plan->apply.at("b")));
  auto rules = lab.IptablesRules("b");
  if (!rules) return rules.error();
  lab.reporter().Record(
      kEventTree,
      {{"scenario", lab.scenario()}, {"drone", "b"}, {"stage", "iptables_cut"}, {"text", *rules}});
  if (auto s = Probe(lab, "cut", "b", 100, 1000); !s) return s.error();
  SWARMBOX_TRY(faults::RunAllCommands(lab.In("b"), plan->undo.at("b")));
  rules = lab.IptablesRules("b");
  if (!rules) return rules.error();
  lab.reporter().Record(
      kEventTree,
      {{"scenario", lab.scenario()}, {"drone", "b"}, {"stage", "iptables_healed"}, {"text", *rules}});
  if (auto s = Probe(lab, "healed", "b", 100, 1000); !s) return s.error();
  return Ok{};
}

Status RunReplace(GuestLab& lab) {
  auto mesh = Mesh("{delay_ms: 20}");
  if (!mesh) return mesh.error();
  auto faults = Faults(
      "[{at: 1s, name: fade_c, radio: {target: a, to: [c], delay_ms: 80}},"
      " {at: 2s, name: storm, radio: {target: a, delay_ms: 30}}]",
      lab.Drones());
  if (!faults) return faults.error();
  SWARMBOX_TRY(ReportTree(lab, "a", "pristine"));
  RadioInjector injector(lab, *mesh);
  SWARMBOX_TRY(injector.ApplyMesh());
  SWARMBOX_TRY(ReportTree(lab, "a", "mesh"));
  SWARMBOX_TRY(injector.ReapplyMesh("a"));
  SWARMBOX_TRY(ReportTree(lab, "a", "mesh_again"));
  if (auto s = Probe(lab, "mesh_to_b", "b", 200, 2000); !s) return s.error();

  SWARMBOX_TRY(
      injector.Apply((*faults)[0]));  // per destination: htb + u32 to c, the mesh's 20 ms for the rest
  SWARMBOX_TRY(ReportTree(lab, "a", "fade_c"));
  if (auto s = Probe(lab, "fade_c_to_b", "b", 200, 2000); !s) return s.error();
  if (auto s = Probe(lab, "fade_c_to_c", "c", 200, 2000); !s) return s.error();
  SWARMBOX_TRY(injector.Remove("fade_c"));
  SWARMBOX_TRY(ReportTree(lab, "a", "fade_c_removed"));
  if (auto s = Probe(lab, "fade_c_removed_to_c", "c", 200, 2000); !s) return s.error();

  SWARMBOX_TRY(injector.Apply((*faults)[1]));  // all traffic: replaces the mesh's rule on a
  SWARMBOX_TRY(ReportTree(lab, "a", "storm"));
  if (auto s = Probe(lab, "storm_to_b", "b", 200, 2000); !s) return s.error();
  SWARMBOX_TRY(injector.Remove("storm"));
  SWARMBOX_TRY(ReportTree(lab, "a", "storm_removed"));

  SWARMBOX_TRY(injector.Undo());
  SWARMBOX_TRY(ReportTree(lab, "a", "undone"));
  if (auto s = Probe(lab, "undone_to_b", "b", 200, 2000); !s) return s.error();
  return Ok{};
}

}  // namespace

const std::vector<Scenario>& AllScenarios() {
  static const std::vector<Scenario> kAll = {
      {"mesh", RunMesh},
      {"fixed", RunFixed},
      {"per_destination", RunPerDestination},
      {"rate", RunRate},
      {"reorder", RunReorder},
      {"duplicate", RunDuplicate},
      {"corrupt", RunCorrupt},
      {"gilbert_elliott", RunGilbertElliott},
      {"partition", RunPartition},
      {"replace", RunReplace},
  };
  return kAll;
}

const Scenario* FindScenario(std::string_view name) {
  for (const Scenario& s : AllScenarios()) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

}  // namespace swarmbox::netem_guest
