// The wiring documented in faults.hpp, carried out against fakes: detection through a sidecar exec,
// the mesh block on every agent, then a schedule driven by clocks and log lines, with an
// events.jsonl line per step. This is the sequence the runner implements.
#include "swarmbox/faults/faults.hpp"

#include <gtest/gtest.h>

#include "support/fake_docker_api.hpp"
#include "test_util.hpp"

namespace swarmbox::faults {
namespace {

using swarmbox::testing::FakeDockerApi;
using testing::Yaml;

TEST(InjectionFlow, MeshThenScheduleOnAHostWithoutNetem) {
  const yaml::Node trial = Yaml(
      "network:\n  mesh: {delay_ms: 100, jitter_ms: 20, loss: 0.05}\n"
      "faults:\n"
      "  - {name: fade, at: 30s, duration: 20s, radio: {target: raft_leader, loss: 0.3}}\n"
      "  - {name: kill_leader, on: \"event=leader_elected\", kill: raft_leader}\n");
  const std::vector<std::string> drones = {"a", "b"};
  auto mesh = ParseMeshBlock(*trial.Find("network")->Find("mesh"));
  auto faults = ParseFaults(*trial.Find("faults"));
  ASSERT_TRUE(mesh && faults);
  ASSERT_TRUE(ValidateFaults(*faults, drones));

  FakeDockerApi api;
  for (const auto& d : drones) {  // each agent and its fault sidecar, running
    api.AddRunning(d);
    api.AddRunning(d + "-faults");
  }
  api.exec_answers["tc qdisc replace dev lo root netem delay 0ms"] = {{}, {"Error: Specified qdisc kind is unknown."}, 2};
  std::map<std::string, std::unique_ptr<DockerExecCommandRunner>> sidecar;
  for (const auto& d : drones) sidecar[d] = std::make_unique<DockerExecCommandRunner>(api, d + "-faults");
  const std::map<std::string, std::string> ip = {{"a", "10.77.2.10"}, {"b", "10.77.2.11"}};
  auto link_of = [&](const std::string& d) {
    LinkTarget l{d, "eth1", {}, kAssumedLinkRateKbit};
    for (const auto& [peer, addr] : ip) {
      if (peer != d) l.peer_ipv4[peer] = addr;
    }
    return l;
  };

  MechanismCache cache;
  auto mech = cache.Get("local", [&] { return DetectMechanism(*sidecar["a"]); });
  ASSERT_TRUE(mech) << mech.error().ToString();
  ASSERT_EQ(*mech, Mechanism::kUserspace);
  ASSERT_TRUE(CheckMechanismSupports(mesh->rules, *mech));

  RadioLayers layers(mesh->rules, drones);
  for (const auto& d : drones) {
    auto plan = PlanRadio(layers.Effective(d), link_of(d), *mech, {});
    ASSERT_TRUE(plan) << plan.error().ToString();
    ASSERT_TRUE(RunCommands(*sidecar[d], plan->apply));
  }

  FaultTimeline timeline(*faults);
  LeaderTracker leaders;
  std::mt19937_64 rng(42);
  std::vector<std::string> events;
  auto carry = [&](const std::vector<TimelineAction>& actions, double sim_s, double wall_s) {
    for (const auto& action : actions) {
      const Fault& f = timeline.faults()[action.fault];
      FaultEventRecord record;
      record.phase = action.kind == TimelineAction::Kind::kApply ? FaultPhase::kApplied : FaultPhase::kRemoved;
      record.t_sim_s = sim_s;
      record.wall_s = wall_s;
      Status s;
      if (const auto* radio = std::get_if<RadioFault>(&f.action)) {
        record.mechanism = std::string(MechanismName(*mech));
        std::vector<std::string> changed;
        std::map<std::string, std::vector<RadioRule>> before;
        for (const auto& d : drones) before[d] = layers.Effective(d);
        if (action.kind == TimelineAction::Kind::kApply) {
          auto targets = ResolveTarget(radio->target, drones, leaders, rng);
          ASSERT_TRUE(targets) << targets.error().ToString();
          record.targets = *targets;
          changed = layers.Push(f.id, *targets, radio->rules);
        } else {
          changed = layers.Pop(f.id);
          record.targets = changed;
        }
        for (const auto& d : changed) {
          auto plan = PlanRadioChange(before[d], layers.Effective(d), link_of(d), *mech, {});
          ASSERT_TRUE(plan) << plan.error().ToString();
          s = RunCommands(*sidecar[d], plan->apply);
        }
      } else if (const auto* process = std::get_if<ProcessFault>(&f.action)) {
        record.mechanism = "docker";
        auto targets = ResolveTarget(process->target, drones, leaders, rng);
        ASSERT_TRUE(targets) << targets.error().ToString();
        record.targets = *targets;
        const ProcessPlan plan = PlanProcessFault(*process, *targets, f.duration_ms.has_value());
        s = ExecuteDockerActions(api, action.kind == TimelineAction::Kind::kApply ? plan.apply : plan.undo);
      }
      ASSERT_TRUE(s) << s.error().ToString();
      events.push_back(FaultEventJson(f, record));
    }
  };

  const std::string elected = "t=12.000 node=b event=leader_elected term=1 leader=b";
  leaders.Feed(elected);
  carry(timeline.OnLogLine(elected, 12.5), 12.0, 12.5);
  carry(timeline.Advance(30.0, 31.0), 30.0, 31.0);
  carry(timeline.Advance(50.0, 51.0), 50.0, 51.0);
  carry(timeline.RemoveAll(), 60.0, 61.0);

  // kill_leader has no duration: its removal at shutdown is recorded with an empty undo plan (the
  // container stays down).
  ASSERT_EQ(events.size(), 4u);
  EXPECT_NE(events[3].find("\"phase\":\"removed\",\"fault\":\"kill_leader\""), std::string::npos) << events[3];
  EXPECT_NE(events[0].find("\"fault\":\"kill_leader\",\"kind\":\"kill\""), std::string::npos) << events[0];
  EXPECT_NE(events[0].find("\"targets\":[\"b\"],\"mechanism\":\"docker\""), std::string::npos) << events[0];
  EXPECT_NE(events[1].find("\"phase\":\"applied\",\"fault\":\"fade\""), std::string::npos) << events[1];
  EXPECT_NE(events[1].find("\"mechanism\":\"userspace-nfqueue\""), std::string::npos) << events[1];
  EXPECT_NE(events[2].find("\"phase\":\"removed\",\"fault\":\"fade\""), std::string::npos) << events[2];
  // The leader was killed through the API, and b's radio went mesh -> fade -> mesh in its sidecar.
  const std::vector<std::string> calls = api.Calls();
  EXPECT_NE(std::find(calls.begin(), calls.end(), "kill b SIGKILL"), calls.end());
  const std::string fade_rule =
      "exec b-faults iptables -w -A SWARMBOX-RADIO-IN -m statistic --mode random --probability 0.3 -j DROP";
  EXPECT_NE(std::find(calls.begin(), calls.end(), fade_rule), calls.end());
  const auto mesh_rule_count = std::count(
      calls.begin(), calls.end(),
      "exec b-faults iptables -w -A SWARMBOX-RADIO-IN -m statistic --mode random --probability 0.05 -j DROP");
  EXPECT_EQ(mesh_rule_count, 2);  // at the start, and again when the fade ended
  EXPECT_EQ(std::count_if(calls.begin(), calls.end(),
                          [](const std::string& c) { return c.rfind("exec a-faults", 0) == 0; }),
            1 + 7);  // the probe, and a's mesh plan only (netemd, 3 egress and 3 ingress rules)
}

}  // namespace
}  // namespace swarmbox::faults
