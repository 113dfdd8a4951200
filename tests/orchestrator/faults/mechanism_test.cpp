#include "swarmbox/faults/mechanism.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace swarmbox::faults {
namespace {

using testing::FakeCommandRunner;
using testing::Yaml;

TEST(Mechanism, ProbeSucceedingMeansKernelNetem) {
  auto m = ClassifyNetemProbe(CommandOutput{0, "", ""});
  ASSERT_TRUE(m);
  EXPECT_EQ(*m, Mechanism::kKernelNetem);
}

TEST(Mechanism, UnknownQdiscKindMeansUserspace) {
  // tc's exact words on this project's machines (issue facts).
  auto m = ClassifyNetemProbe(CommandOutput{2, "", "Error: Specified qdisc kind is unknown.\n"});
  ASSERT_TRUE(m);
  EXPECT_EQ(*m, Mechanism::kUserspace);
  EXPECT_EQ(MechanismName(*m), "userspace-nfqueue");
}

TEST(Mechanism, OtherTcFailuresAreReportedNotGuessed) {
  auto m = ClassifyNetemProbe(CommandOutput{2, "", "RTNETLINK answers: Operation not permitted\n"});
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(m.error().message(),
            "cannot tell whether the kernel has sch_netem: the tc probe exited 2: RTNETLINK answers: Operation not "
            "permitted");
}

TEST(Mechanism, DetectRunsTheProbeOnLoopbackAndRemovesIt) {
  FakeCommandRunner runner;
  auto m = DetectMechanism(runner);
  ASSERT_TRUE(m);
  EXPECT_EQ(*m, Mechanism::kKernelNetem);
  EXPECT_EQ(runner.calls, (std::vector<std::string>{"tc qdisc replace dev lo root netem delay 0ms",
                                                     "tc qdisc del dev lo root"}));
}

TEST(Mechanism, DetectWithoutNetemLeavesNothingToRemove) {
  FakeCommandRunner runner;
  runner.answers["tc qdisc"] = CommandOutput{2, "", "Error: Specified qdisc kind is unknown.\n"};
  auto m = DetectMechanism(runner);
  ASSERT_TRUE(m);
  EXPECT_EQ(*m, Mechanism::kUserspace);
  EXPECT_EQ(runner.calls.size(), 1u);
}

TEST(Mechanism, CacheDetectsOncePerHost) {
  MechanismCache cache;
  int probes = 0;
  auto detect = [&]() -> Result<Mechanism> {
    ++probes;
    return Mechanism::kUserspace;
  };
  ASSERT_TRUE(cache.Get("host-a", detect));
  ASSERT_TRUE(cache.Get("host-a", detect));
  ASSERT_TRUE(cache.Get("host-b", detect));
  EXPECT_EQ(probes, 2);
}

TEST(Mechanism, CacheDoesNotKeepFailures) {
  MechanismCache cache;
  int probes = 0;
  auto failing = [&]() -> Result<Mechanism> {
    ++probes;
    return Error(ErrorCode::kUnavailable, "no engine");
  };
  EXPECT_FALSE(cache.Get("h", failing));
  EXPECT_FALSE(cache.Get("h", failing));
  EXPECT_EQ(probes, 2);
}

TEST(Mechanism, UserspaceSupportTable) {
  struct Case {
    const char* yaml;
    const char* refused_key;  // "" = supported
  };
  const Case cases[] = {
      {"{delay_ms: 10, jitter_ms: 3, distribution: paretonormal, correlation: 0.5, reorder: 0.1}", ""},
      {"{loss: 0.1, rate_kbit: 100}", ""},
      {"{loss: 0.1, loss_correlation: 0.2}", "'loss_correlation'"},
      {"{gilbert_elliott: {p: 0.1, r: 0.2}}", ""},  // drawn by swarmbox-netemd
      {"{duplicate: 0.1}", ""},  // iptables TEE
      {"{corrupt: 0.1}", ""},  // a bit flipped by swarmbox-netemd
  };
  for (const Case& c : cases) {
    auto rules = ParseRadioRules(Yaml(c.yaml), "radio");
    ASSERT_TRUE(rules) << rules.error().ToString();
    EXPECT_TRUE(CheckMechanismSupports(*rules, Mechanism::kKernelNetem)) << c.yaml;
    Status s = CheckMechanismSupports(*rules, Mechanism::kUserspace);
    if (std::string(c.refused_key).empty()) {
      EXPECT_TRUE(s) << c.yaml << ": " << s.error().message();
    } else {
      ASSERT_FALSE(s) << c.yaml;
      EXPECT_EQ(s.error().message().rfind(c.refused_key, 0), 0u) << s.error().message();
      EXPECT_NE(s.error().message().find("the kernel has no sch_netem"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace swarmbox::faults
