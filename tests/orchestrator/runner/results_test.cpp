#include "swarmbox/runner/results.hpp"

#include <gtest/gtest.h>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::runner {
namespace {

// The start's and end's wall times; what did not happen is null.
TEST(ResultJson, TimingHoldsTheStartAndTheTeardown) {
  TrialResult r;
  r.timing = {22, 3.4, 15.5, std::nullopt, 4.125};
  auto doc = yaml::Parse(ResultJson(r), "result.json");
  ASSERT_TRUE(doc) << doc.error().ToString();
  const yaml::Node* t = doc->Find("timing");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->Find("containers")->scalar(), "22");
  EXPECT_EQ(t->Find("created_s")->scalar(), "3.4");
  EXPECT_EQ(t->Find("started_s")->scalar(), "15.5");
  EXPECT_TRUE(t->Find("joined_s")->is_null());
  EXPECT_EQ(t->Find("teardown_s")->scalar(), "4.125");
}

TEST(ResultJson, HoldsTheContractFields) {
  TrialResult r;
  r.trial = "sar-search";
  r.trial_id = "sar-search";
  r.run_id = "20261121-101000-7f3a";
  r.verdict = dsl::Verdict::Failure("collision", "scout_2");
  r.wall_s = 312.5;
  r.sim_s = 300.25;
  r.seed = 42;
  r.host = "local";
  r.metrics = {{"collisions", 1}, {"victims_confirmed", 2}};
  r.components = {{"physics", 0, false, "logs/physics.log", 1200}, {"scout_2", std::nullopt, false, "logs/scout_2.log", 3}};
  r.problems = {"trajectories.png not drawn: no truth.csv was collected"};
  auto doc = yaml::Parse(ResultJson(r), "result.json");
  ASSERT_TRUE(doc) << doc.error().ToString();
  for (const char* key : {"trial", "outcome", "reason", "wall_s", "sim_s", "seed", "host", "metrics"}) {
    EXPECT_NE(doc->Find(key), nullptr) << key;
  }
  EXPECT_EQ(doc->Find("outcome")->scalar(), "failure");
  EXPECT_EQ(doc->Find("reason")->scalar(), "collision");
  EXPECT_EQ(doc->Find("wall_s")->scalar(), "312.5");
  EXPECT_EQ(doc->Find("sim_s")->scalar(), "300.25");
  EXPECT_EQ(doc->Find("metrics")->Find("victims_confirmed")->scalar(), "2");
  EXPECT_TRUE(doc->Find("components")->items()[1].Find("exit_code")->is_null());
  EXPECT_EQ(doc->Find("problems")->items().size(), 1u);
}

TEST(ResultJson, MetricsAreResultsCsvsColumnsNullWhenUnknownAndProvenanceIsOneObject) {
  TrialResult r;
  r.metrics = {{"victims_confirmed", 2.0}, {"radio_loss", 0.0079412}, {"failover_s", std::nullopt}};
  r.provenance.swarmbox_version = "0.1.0";
  r.provenance.swarmbox_commit = "1a2b3c4d5e6f";
  r.provenance.images = {"swarmbox/agent:aa", "swarmbox/physics:bb"};
  r.provenance.engine = {"20.10.24+dfsg1", "1.41", "6.1.0-18-amd64"};
  r.provenance.fault_mechanism = "netem";
  r.provenance.rtf_requested = 0;
  r.provenance.rtf_achieved = 3.25;
  r.provenance.host_name = "lab-3";
  auto doc = yaml::Parse(ResultJson(r), "result.json");
  ASSERT_TRUE(doc) << doc.error().ToString();
  const yaml::Node* metrics = doc->Find("metrics");
  ASSERT_NE(metrics, nullptr);
  for (const std::string& name : report::MetricNames()) EXPECT_NE(metrics->Find(name), nullptr) << name;
  EXPECT_EQ(metrics->Find("victims_confirmed")->scalar(), "2");
  EXPECT_EQ(metrics->Find("radio_loss")->scalar(), "0.007941");  // as results.csv writes it
  EXPECT_TRUE(metrics->Find("failover_s")->is_null());
  EXPECT_TRUE(metrics->Find("victims_rescued")->is_null());
  const yaml::Node* p = doc->Find("provenance");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->Find("swarmbox_commit")->scalar(), "1a2b3c4d5e6f");
  EXPECT_EQ(p->Find("images")->items().size(), 2u);
  EXPECT_EQ(p->Find("docker_api_version")->scalar(), "1.41");
  EXPECT_EQ(p->Find("kernel")->scalar(), "6.1.0-18-amd64");
  EXPECT_EQ(p->Find("fault_mechanism")->scalar(), "netem");
  EXPECT_EQ(p->Find("rtf_requested")->scalar(), "0");
  EXPECT_EQ(p->Find("rtf_achieved")->scalar(), "3.25");
  EXPECT_EQ(p->Find("host_name")->scalar(), "lab-3");
}

TEST(RtfMeter, SimulatedOverWallSecondsFromTheFirstMoveOfSimulatedTime) {
  RtfMeter m;
  EXPECT_FALSE(m.Achieved());
  m.Observe(0.5, 0.0);  // containers starting: no simulated time yet
  m.Observe(2.0, 0.0);
  EXPECT_FALSE(m.Achieved());
  m.Observe(3.0, 0.1);
  EXPECT_FALSE(m.Achieved());  // one observation: no span yet
  m.Observe(13.0, 40.1);
  ASSERT_TRUE(m.Achieved());
  EXPECT_DOUBLE_EQ(*m.Achieved(), 4.0);
}

TEST(ResultJson, ListsTheContainersKilledForLackOfMemory) {
  TrialResult r;
  r.verdict = dsl::Verdict::Failure("scout_2 was killed for lack of memory", "scout_2");
  r.components = {{"physics", 0, false, "logs/physics.log", 10},
                  {"scout_2", 137, true, "logs/scout_2.log", 3}};
  auto doc = yaml::Parse(ResultJson(r), "result.json");
  ASSERT_TRUE(doc) << doc.error().ToString();
  const yaml::Node* oom = doc->Find("oom_killed");
  ASSERT_NE(oom, nullptr);
  ASSERT_EQ(oom->items().size(), 1u);
  EXPECT_EQ(oom->items()[0].scalar(), "scout_2");
  EXPECT_EQ(doc->Find("components")->items()[1].Find("oom_killed")->scalar(), "true");
  r.components[1].oom_killed = false;
  doc = yaml::Parse(ResultJson(r), "result.json");
  ASSERT_TRUE(doc);
  EXPECT_TRUE(doc->Find("oom_killed")->items().empty());  // always there, empty when none
}

TEST(EventsJsonl, LogEventsKeepTheirFieldsNumbersBare) {
  auto j = LogEventJson(1.5, "scout_1", ParseLogfmt("t=12.340 node=drone_2 event=leader_elected term=3 msg=\"a b\""));
  ASSERT_TRUE(j);
  EXPECT_EQ(*j,
            "{\"wall_s\":1.5,\"component\":\"scout_1\",\"t\":12.340,\"node\":\"drone_2\","
            "\"event\":\"leader_elected\",\"term\":3,\"msg\":\"a b\"}");
  EXPECT_FALSE(LogEventJson(1.5, "scout_1", ParseLogfmt("t=1 node=x")).has_value());
  // Odd values stay strings (JSON has no inf/nan or hex).
  auto odd = LogEventJson(0, "x", ParseLogfmt("event=e a=inf b=0x10 c=.5"));
  ASSERT_TRUE(odd);
  EXPECT_EQ(*odd, "{\"wall_s\":0,\"component\":\"x\",\"event\":\"e\",\"a\":\"inf\",\"b\":\"0x10\",\"c\":\".5\"}");
}

TEST(EventsJsonl, LifecycleEvents) {
  EXPECT_EQ(LifecycleEventJson(0.25, "run", "physics", dsl::Verdict::Success()),
            "{\"wall_s\":0.25,\"component\":\"orchestrator\",\"event\":\"run\",\"target\":\"physics\","
            "\"outcome\":\"success\"}");
  EXPECT_EQ(LifecycleEventJson(3, "build", "sim", dsl::Verdict::Err("subnet")),
            "{\"wall_s\":3,\"component\":\"orchestrator\",\"event\":\"build\",\"target\":\"sim\","
            "\"outcome\":\"error\",\"reason\":\"subnet\"}");
}

TEST(ExitCodeFor, FollowsTheCliContract) {
  EXPECT_EQ(ExitCodeFor(dsl::Verdict::Success()), 0);
  EXPECT_EQ(ExitCodeFor(dsl::Verdict::Timeout("t")), 1);
  EXPECT_EQ(ExitCodeFor(dsl::Verdict::Failure("f")), 1);
  EXPECT_EQ(ExitCodeFor(dsl::Verdict::Err("e")), 3);
}

}  // namespace
}  // namespace swarmbox::runner
