// The shipped trials/faults/*.yaml: one per fault family, each parsed and validated with this
// library's parsers, and every fault planned for the mechanisms it claims to run on.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <set>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/faults/fault_spec.hpp"
#include "swarmbox/faults/leader_tracker.hpp"
#include "swarmbox/faults/mechanism.hpp"
#include "swarmbox/faults/partition_plan.hpp"
#include "swarmbox/faults/physics_plan.hpp"
#include "swarmbox/faults/process_plan.hpp"
#include "swarmbox/faults/radio_plan.hpp"
#include "swarmbox/faults/target_resolver.hpp"

namespace swarmbox::faults {
namespace {

namespace fs = std::filesystem;

struct TrialFaults {
  std::string file;
  std::vector<std::string> drones;
  MeshImpairment mesh;
  std::vector<Fault> faults;
};

Result<TrialFaults> Load(const fs::path& path) {
  auto doc = yaml::ParseFile(path.string());
  if (!doc) return doc.error();
  TrialFaults t;
  t.file = path.filename().string();
  const yaml::Node* drones = doc->Find("drones");
  if (drones == nullptr || !drones->is_sequence()) {
    return Error(ErrorCode::kInvalidArgument, "no drones list", path.string());
  }
  for (const auto& d : drones->items()) {
    std::string name;
    SWARMBOX_TRY(yaml::Decode(*d.Find("name"), &name));
    t.drones.push_back(name);
  }
  if (const yaml::Node* network = doc->Find("network")) {
    if (const yaml::Node* mesh = network->Find("mesh")) {
      auto m = ParseMeshBlock(*mesh);
      if (!m) return m.error();
      t.mesh = *m;
      SWARMBOX_TRY(ValidateRadioPeers(t.mesh.rules, t.drones));
    }
  }
  const yaml::Node* faults = doc->Find("faults");
  auto parsed = ParseFaults(faults != nullptr ? *faults : yaml::Node());
  if (!parsed) return parsed.error();
  t.faults = std::move(*parsed);
  SWARMBOX_TRY(ValidateFaults(t.faults, t.drones));
  return t;
}

std::vector<fs::path> TrialFiles() {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(SWARMBOX_TRIALS_FAULTS_DIR)) {
    if (e.path().extension() == ".yaml") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Mesh addresses as the runner assigns them: 10.77.2.10 + index.
std::vector<MeshNode> Nodes(const std::vector<std::string>& drones) {
  std::vector<MeshNode> nodes;
  for (std::size_t i = 0; i < drones.size(); ++i) {
    nodes.push_back({drones[i], "eth1", "10.77.2." + std::to_string(10 + i)});
  }
  return nodes;
}

LinkTarget LinkOf(const std::string& node, const std::vector<MeshNode>& nodes) {
  LinkTarget link;
  link.node = node;
  link.mesh_interface = "eth1";
  for (const auto& n : nodes) {
    if (n.name != node) link.peer_ipv4[n.name] = n.ipv4;
  }
  return link;
}

TEST(FaultTrialFiles, EveryFileParsesAndValidates) {
  const auto files = TrialFiles();
  ASSERT_GE(files.size(), 4u) << "trials/faults/ should hold one trial per fault family";
  for (const auto& path : files) {
    auto t = Load(path);
    EXPECT_TRUE(t) << path << ": " << t.error().ToString();
  }
}

TEST(FaultTrialFiles, TogetherTheyCoverEveryFaultKindAndStart) {
  std::set<std::string> kinds;
  std::set<FaultStart::Clock> clocks;
  std::set<FaultTarget::Kind> targets;
  for (const auto& path : TrialFiles()) {
    auto t = Load(path);
    ASSERT_TRUE(t) << t.error().ToString();
    for (const auto& f : t->faults) {
      kinds.insert(std::string(f.kind()));
      clocks.insert(f.start.clock);
      if (const FaultTarget* target = f.target()) targets.insert(target->kind);
    }
  }
  EXPECT_EQ(kinds, (std::set<std::string>{"gps_degrade", "gps_dropout", "imu_bias", "kill", "partition", "pause", "radio", "restart",
                                          "stop", "wind_gust"}));
  EXPECT_EQ(clocks.size(), 3u);   // at, at_wall, on
  EXPECT_EQ(targets.size(), 5u);  // names, pattern, all, raft_leader, random
}

TEST(FaultTrialFiles, EveryFaultPlansOnTheMechanismsItClaims) {
  for (const auto& path : TrialFiles()) {
    auto t = Load(path);
    ASSERT_TRUE(t) << t.error().ToString();
    const bool kernel_only = t->file == "radio_kernel_only.yaml";
    const auto nodes = Nodes(t->drones);
    LeaderTracker leaders;
    leaders.Feed("t=10.000 node=" + t->drones.back() + " event=leader_elected term=1 leader=" + t->drones.back());
    std::mt19937_64 rng(42);
    for (const auto& f : t->faults) {
      SCOPED_TRACE(t->file + " " + f.id);
      if (const auto* radio = std::get_if<RadioFault>(&f.action)) {
        auto names = ResolveTarget(radio->target, t->drones, leaders, rng);
        ASSERT_TRUE(names) << names.error().ToString();
        for (const auto& name : *names) {
          const auto rules = ComposeRadio(t->mesh.rules, radio->rules);
          auto kernel = PlanRadio(rules, LinkOf(name, nodes), Mechanism::kKernelNetem);
          ASSERT_TRUE(kernel) << kernel.error().ToString();
          EXPECT_FALSE(kernel->apply.empty());
          auto user = PlanRadio(rules, LinkOf(name, nodes), Mechanism::kUserspace);
          if (kernel_only) {
            ASSERT_FALSE(user);
            EXPECT_NE(user.error().message().find("the kernel has no sch_netem"), std::string::npos);
          } else {
            ASSERT_TRUE(user) << user.error().ToString();
            EXPECT_FALSE(user->apply.empty());
            EXPECT_EQ(user->undo.empty(), false);
          }
        }
      } else if (const auto* partition = std::get_if<PartitionFault>(&f.action)) {
        auto plan = PlanPartition(*partition, nodes);
        ASSERT_TRUE(plan) << plan.error().ToString();
        EXPECT_FALSE(plan->apply.empty());
        EXPECT_EQ(plan->apply.size(), plan->undo.size());
      } else if (const auto* process = std::get_if<ProcessFault>(&f.action)) {
        auto names = ResolveTarget(process->target, t->drones, leaders, rng);
        ASSERT_TRUE(names) << names.error().ToString();
        const ProcessPlan plan = PlanProcessFault(*process, *names, f.duration_ms.has_value());
        EXPECT_EQ(plan.apply.size(), names->size());
      } else if (IsPhysicsFault(f)) {
        std::vector<std::string> names;
        if (const FaultTarget* target = f.target()) {
          auto resolved = ResolveTarget(*target, t->drones, leaders, rng);
          ASSERT_TRUE(resolved) << resolved.error().ToString();
          names = *resolved;
        }
        const PhysicsPlan plan = PlanPhysicsFault(f, names);
        EXPECT_EQ(plan.apply.size(), f.target() != nullptr ? names.size() : 1u);
      } else {
        ADD_FAILURE() << "no plan check for fault kind " << f.kind();
      }
    }
    // The mesh block itself runs on this project's machines.
    EXPECT_TRUE(CheckMechanismSupports(t->mesh.rules, Mechanism::kUserspace)) << t->file;
  }
}

}  // namespace
}  // namespace swarmbox::faults
