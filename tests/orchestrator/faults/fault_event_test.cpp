#include "swarmbox/faults/fault_event.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace swarmbox::faults {
namespace {

using testing::Yaml;

Fault First(const std::string& yaml) {
  auto faults = ParseFaults(Yaml(yaml));
  EXPECT_TRUE(faults) << faults.error().ToString();
  return faults ? (*faults)[0] : Fault{};
}

TEST(FaultEvent, RadioAppliedSaysWhichMechanismRan) {
  const Fault f = First("- {at: 30s, duration: 20s, radio: {target: scout_1, delay_ms: 100, jitter_ms: 20, "
                        "distribution: normal, loss: 0.05}}");
  FaultEventRecord r;
  r.phase = FaultPhase::kApplied;
  r.t_sim_s = 30.0126;
  r.wall_s = 31.4;
  r.targets = {"scout_1"};
  r.mechanism = "userspace-nfqueue";
  EXPECT_EQ(FaultEventJson(f, r),
            "{\"type\":\"fault\",\"phase\":\"applied\",\"fault\":\"fault_0\",\"kind\":\"radio\",\"start\":\"at 30s\","
            "\"t_sim_s\":30.013,\"wall_s\":31.4,\"targets\":[\"scout_1\"],\"mechanism\":\"userspace-nfqueue\","
            "\"spec\":\"delay_ms=100 jitter_ms=20 distribution=normal loss=0.05 duration=20s\"}");
}

TEST(FaultEvent, FailedCarriesTheError) {
  const Fault f = First("- {name: kill_leader, on: \"event=leader_elected\", kill: raft_leader}");
  FaultEventRecord r;
  r.phase = FaultPhase::kFailed;
  r.mechanism = "docker";
  r.error = "kill t1-scout_2 SIGKILL: container is not running";
  const std::string json = FaultEventJson(f, r);
  EXPECT_NE(json.find("\"phase\":\"failed\""), std::string::npos);
  EXPECT_NE(json.find("\"fault\":\"kill_leader\""), std::string::npos);
  EXPECT_NE(json.find("\"start\":\"on event=leader_elected\""), std::string::npos);
  EXPECT_NE(json.find("\"spec\":\"signal=SIGKILL\""), std::string::npos);
  EXPECT_NE(json.find("\"error\":\"kill t1-scout_2 SIGKILL: container is not running\""), std::string::npos);
  // It is one line of valid JSON: the YAML reader reads it back.
  auto back = yaml::Parse(json);
  ASSERT_TRUE(back) << back.error().ToString();
  EXPECT_EQ(*back->Find("targets"), yaml::Node::Sequence());
}

TEST(FaultEvent, MeshImpairmentRecordsItsMechanism) {
  auto mesh = ParseMeshBlock(Yaml("{delay_ms: 100, jitter_ms: 20, loss: 0.05}"));
  ASSERT_TRUE(mesh);
  FaultEventRecord r;
  r.wall_s = 0.8;
  r.mechanism = "userspace-nfqueue";
  EXPECT_EQ(MeshEventJson("scout_1", mesh->rules, r),
            "{\"type\":\"mesh\",\"phase\":\"applied\",\"node\":\"scout_1\",\"t_sim_s\":0,\"wall_s\":0.8,"
            "\"mechanism\":\"userspace-nfqueue\",\"spec\":\"delay_ms=100 jitter_ms=20 loss=0.05\"}");
}

TEST(FaultEvent, UserspaceCorruptionIsRecordedWithItsMechanism) {
  auto mesh = ParseMeshBlock(Yaml("{corrupt: 0.1}"));
  ASSERT_TRUE(mesh);
  FaultEventRecord r;
  r.wall_s = 0.8;
  r.mechanism = "userspace-nfqueue";  // swarmbox-netemd flips the bits
  EXPECT_EQ(MeshEventJson("scout_1", mesh->rules, r),
            "{\"type\":\"mesh\",\"phase\":\"applied\",\"node\":\"scout_1\",\"t_sim_s\":0,\"wall_s\":0.8,"
            "\"mechanism\":\"userspace-nfqueue\",\"spec\":\"corrupt=0.1\"}");
}

TEST(FaultEvent, DescribesEveryKind) {
  EXPECT_EQ(DescribeFault(First("- {at: 1s, duration: 30s, partition: {groups: [[a, b], [c]], oneway: true}}")),
            "groups=[[a, b], [c]] oneway=true duration=30s");
  EXPECT_EQ(DescribeFault(First("- {at: 1s, stop: {target: a, timeout: 3s}}")), "timeout_s=3");
  EXPECT_EQ(DescribeFault(First("- {at: 1s, duration: 2s, gps_dropout: a}")), "duration=2s");
  EXPECT_EQ(DescribeFault(First("- {at: 1s, duration: 4s, gps_degrade: {target: a, h_acc_m: 5, v_acc_m: 8.5}}")),
            "h_acc_m=5 v_acc_m=8.5 duration=4s");
  EXPECT_EQ(DescribeFault(First("- {at: 1s, wind_gust: {speed_m_s: 12, direction_deg: 270}}")),
            "speed_m_s=12 direction_deg=270 vertical_m_s=0");
  EXPECT_EQ(DescribeFault(First("- {at: 1s, radio: {rules: [{to: [b], delay_ms: 5}, {rate_kbit: 64}]}}")),
            "delay_ms=5 to=[b]; rate_kbit=64");
}

}  // namespace
}  // namespace swarmbox::faults
