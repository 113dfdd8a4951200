#include "swarmbox/faults/netem_spec.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace swarmbox::faults {
namespace {

using testing::Yaml;

TEST(NetemSpec, ParsesEveryKey) {
  auto rules = ParseRadioRules(Yaml("{delay_ms: 100, jitter_ms: 20, distribution: normal, correlation: 0.25,\n"
                                    " loss: 0.05, loss_correlation: 0.1, duplicate: 0.01, corrupt: 0.001,\n"
                                    " reorder: 0.2, reorder_correlation: 0.5, reorder_gap: 5, rate_kbit: 2000,\n"
                                    " limit: 5000}"),
                               "radio");
  ASSERT_TRUE(rules) << rules.error().ToString();
  ASSERT_EQ(rules->size(), 1u);
  const NetemSpec& s = (*rules)[0].spec;
  EXPECT_EQ(s.delay_ms, 100);
  EXPECT_EQ(s.jitter_ms, 20);
  EXPECT_EQ(s.distribution, DelayDistribution::kNormal);
  EXPECT_EQ(s.correlation, 0.25);
  EXPECT_EQ(s.loss, 0.05);
  EXPECT_EQ(s.loss_correlation, 0.1);
  EXPECT_EQ(s.duplicate, 0.01);
  EXPECT_EQ(s.corrupt, 0.001);
  EXPECT_EQ(s.reorder, 0.2);
  EXPECT_EQ(s.reorder_correlation, 0.5);
  EXPECT_EQ(s.reorder_gap, 5u);
  EXPECT_EQ(s.rate_kbit, 2000.0);
  EXPECT_EQ(s.limit_packets, 5000u);
  EXPECT_TRUE((*rules)[0].to.empty());
}

TEST(NetemSpec, ParsesGilbertElliottAndPerDestinationRules) {
  auto rules = ParseRadioRules(Yaml("rules:\n"
                                    "  - {to: [scout_2], delay_ms: 300}\n"
                                    "  - {to: [lifter, scout_3], gilbert_elliott: {p: 0.05, r: 0.5, loss_bad: 0.9}}\n"),
                               "radio");
  ASSERT_TRUE(rules) << rules.error().ToString();
  ASSERT_EQ(rules->size(), 2u);
  EXPECT_EQ((*rules)[0].to, std::vector<std::string>{"scout_2"});
  ASSERT_TRUE((*rules)[1].spec.gilbert_elliott.has_value());
  EXPECT_EQ(*(*rules)[1].spec.gilbert_elliott, (GilbertElliott{0.05, 0.5, 0.9, 0.0}));
  EXPECT_EQ((*rules)[1].mark.line, 3);
}

struct BadSpec {
  const char* yaml;
  const char* where;    // file:line:col of the report
  const char* message;  // a part of the message
};

class NetemSpecRejects : public ::testing::TestWithParam<BadSpec> {};

TEST_P(NetemSpecRejects, WithReasonAndPlace) {
  auto rules = ParseRadioRules(Yaml(GetParam().yaml), "radio");
  ASSERT_FALSE(rules);
  EXPECT_EQ(rules.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(rules.error().where(), GetParam().where);
  EXPECT_NE(rules.error().message().find(GetParam().message), std::string::npos) << rules.error().message();
}

INSTANTIATE_TEST_SUITE_P(
    Cases, NetemSpecRejects,
    ::testing::Values(
        BadSpec{"{delay_ms: 10, jitter_ms: 5, distribution: weibull}", "trial.yaml:1:44",
                "distribution 'weibull' is supported by neither mechanism"},
        BadSpec{"{loss: 1.5}", "trial.yaml:1:8", "'loss' is a probability in [0, 1]"},
        BadSpec{"{loss: -0.1}", "trial.yaml:1:8", "'loss' is a probability in [0, 1]"},
        BadSpec{"{loss: 5}", "trial.yaml:1:8", "a fraction, not percent"},
        BadSpec{"{delay_ms: 10, distribution: normal}", "trial.yaml:1:30", "needs jitter_ms > 0"},
        BadSpec{"{reorder: 0.1}", "trial.yaml:1:11", "'reorder' needs delay_ms > 0"},
        BadSpec{"{loss: 0.1, gilbert_elliott: {p: 0.1, r: 0.2}}", "trial.yaml:1:30", "not both"},
        BadSpec{"{rate_kbit: 0}", "trial.yaml:1:13", "'rate_kbit' must be > 0"},
        BadSpec{"{delay_ms: -1}", "trial.yaml:1:12", "'delay_ms' must be >= 0"},
        BadSpec{"{delay_ms: 10, latency: 3}", "trial.yaml:1:16", "unknown key 'latency' in radio"},
        BadSpec{"{}", "trial.yaml:1:1", "radio impairs nothing"},
        BadSpec{"{to: [], loss: 0.1}", "trial.yaml:1:6", "an empty list impairs nothing"},
        BadSpec{"{gilbert_elliott: {p: 2, r: 0.2}}", "trial.yaml:1:23", "'p' is a probability"}));

TEST(NetemSpec, ValidatesPeersAgainstTheTrialsDrones) {
  auto rules = ParseRadioRules(Yaml("rules:\n  - {to: [scout_9], delay_ms: 300}\n"), "radio");
  ASSERT_TRUE(rules) << rules.error().ToString();
  Status s = ValidateRadioPeers(*rules, {"scout_1", "scout_2"});
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().where(), "trial.yaml:2:5");
  EXPECT_EQ(s.error().message(), "per-destination rule names unknown peer 'scout_9' (drones: scout_1, scout_2)");
}

TEST(NetemSpec, RefusesAPeerInTwoRules) {
  auto rules = ParseRadioRules(Yaml("rules: [{to: [a], loss: 0.1}, {to: [b, a], loss: 0.2}]"), "radio");
  ASSERT_TRUE(rules) << rules.error().ToString();
  Status s = ValidateRadioPeers(*rules, {"a", "b"});
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().message(), "peer 'a' appears in two per-destination rules");
}

TEST(NetemSpec, MeshBlockAsInTheArchitectureExample) {
  auto doc = Yaml("network:\n  mesh: {delay_ms: 100, jitter_ms: 20, loss: 0.05}\n");
  auto mesh = ParseMeshBlock(*doc.Find("network")->Find("mesh"));
  ASSERT_TRUE(mesh) << mesh.error().ToString();
  ASSERT_EQ(mesh->rules.size(), 1u);
  EXPECT_EQ(mesh->rules[0].spec.delay_ms, 100);
  EXPECT_EQ(mesh->rules[0].spec.jitter_ms, 20);
  EXPECT_EQ(mesh->rules[0].spec.loss, 0.05);
}

TEST(NetemSpec, MeshBlockOverriddenToNothingImpairsNothing) {
  // What `--set network.mesh.loss=0` leaves when loss was the only key.
  auto mesh = ParseMeshBlock(Yaml("{loss: 0}"));
  ASSERT_TRUE(mesh) << mesh.error().ToString();
  EXPECT_TRUE(mesh->empty());
  auto absent = ParseMeshBlock(yaml::Node());
  ASSERT_TRUE(absent);
  EXPECT_TRUE(absent->empty());
}

TEST(NetemSpec, MeshBlockStillRefusesBadValues) {
  auto mesh = ParseMeshBlock(Yaml("{loss: 0.1, jitter_ms: 3, distribution: cauchy}"));
  ASSERT_FALSE(mesh);
  EXPECT_NE(mesh.error().message().find("distribution 'cauchy'"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::faults
