#include "swarmbox/faults/fault_timeline.hpp"

#include <gtest/gtest.h>

#include "swarmbox/faults/radio_layers.hpp"
#include "test_util.hpp"

namespace swarmbox::faults {
namespace {

using A = TimelineAction;
using K = TimelineAction::Kind;
using testing::Yaml;

std::vector<Fault> Faults(const std::string& yaml) {
  auto f = ParseFaults(Yaml(yaml));
  EXPECT_TRUE(f) << f.error().ToString();
  return f ? *f : std::vector<Fault>{};
}

TEST(FaultTimeline, SimAndWallStartsWithDurations) {
  FaultTimeline t(Faults("- {at: 30s, duration: 20s, pause: a}\n"
                         "- {at_wall: 10s, duration: 5s, stop: b}\n"
                         "- {at: 40s, kill: c}\n"));
  EXPECT_TRUE(t.Advance(29.9, 9.9).empty());
  EXPECT_EQ(t.Advance(30.0, 10.0), (std::vector<A>{{K::kApply, 0}, {K::kApply, 1}}));
  EXPECT_TRUE(t.Advance(35.0, 14.9).empty());
  EXPECT_EQ(t.Advance(40.0, 15.0), (std::vector<A>{{K::kRemove, 1}, {K::kApply, 2}}));
  EXPECT_EQ(t.Advance(50.0, 25.0), (std::vector<A>{{K::kRemove, 0}}));
  EXPECT_TRUE(t.Advance(60.0, 35.0).empty());
  EXPECT_TRUE(t.active(2));  // no duration: active until the end
  EXPECT_EQ(t.RemoveAll(), (std::vector<A>{{K::kRemove, 2}}));
  EXPECT_TRUE(t.RemoveAll().empty());
}

TEST(FaultTimeline, EventStartsFireOnceOnAMatchingLineAndLastOnWallTime) {
  FaultTimeline t(Faults("- {on: \"event=leader_elected\", duration: 2s, kill: raft_leader}"));
  EXPECT_TRUE(t.OnLogLine("t=3.000 node=a event=leader_elected_late term=1", 5.0).empty());
  EXPECT_TRUE(t.OnLogLine("t=3.000 node=a event=takeoff", 5.0).empty());
  EXPECT_EQ(t.OnLogLine("t=3.100 node=a event=leader_elected term=1 leader=a", 5.5), (std::vector<A>{{K::kApply, 0}}));
  EXPECT_TRUE(t.OnLogLine("t=9.000 node=b event=leader_elected term=2 leader=b", 6.0).empty());
  EXPECT_TRUE(t.Advance(100.0, 7.4).empty());  // simulated time does not end it
  EXPECT_EQ(t.Advance(100.0, 7.5), (std::vector<A>{{K::kRemove, 0}}));
}

TEST(FaultTimeline, CoarseTimerAppliesAndRemovesAPassedWindow) {
  FaultTimeline t(Faults("- {at: 1s, duration: 1s, pause: a}"));
  EXPECT_EQ(t.Advance(5.0, 5.0), (std::vector<A>{{K::kApply, 0}, {K::kRemove, 0}}));
}

TEST(FaultTimeline, RemoveAllUndoesNewestFirst) {
  FaultTimeline t(Faults("- {at: 1s, pause: a}\n- {at: 2s, radio: {loss: 0.1}}\n- {at: 3s, stop: b}"));
  t.Advance(1.0, 0);
  t.Advance(3.0, 0);
  EXPECT_EQ(t.RemoveAll(), (std::vector<A>{{K::kRemove, 2}, {K::kRemove, 1}, {K::kRemove, 0}}));
}

TEST(FaultTimeline, LogLineMatchingNeedsEveryPair) {
  EXPECT_TRUE(LogLineMatches("t=1 node=b event=victim_confirmed id=3", "event=victim_confirmed node=b"));
  EXPECT_FALSE(LogLineMatches("t=1 node=a event=victim_confirmed id=3", "event=victim_confirmed node=b"));
  EXPECT_FALSE(LogLineMatches("anything", ""));
}

std::vector<RadioRule> Rules(const std::string& yaml) {
  auto r = ParseRadioRules(Yaml(yaml), "radio");
  EXPECT_TRUE(r) << r.error().ToString();
  return r ? *r : std::vector<RadioRule>{};
}

TEST(RadioLayers, FaultsStackOverTheMeshAndComeOffInAnyOrder) {
  const auto base = Rules("{loss: 0.05}");
  RadioLayers layers(base, {"a", "b", "c"});
  EXPECT_EQ(layers.Effective("a"), base);
  const auto fade = Rules("{delay_ms: 200}");
  const auto to_c = Rules("{to: [c], loss: 0.5}");
  EXPECT_EQ(layers.Push("fade", {"a", "b"}, fade), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(layers.Push("to_c", {"a"}, to_c), (std::vector<std::string>{"a"}));
  auto a = layers.Effective("a");
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0], fade[0]);
  EXPECT_EQ(a[1], to_c[0]);
  EXPECT_EQ(layers.Pop("fade"), (std::vector<std::string>{"a", "b"}));
  a = layers.Effective("a");
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0], base[0]);
  EXPECT_EQ(a[1], to_c[0]);
  EXPECT_EQ(layers.Effective("b"), base);
  EXPECT_EQ(layers.Pop("to_c"), (std::vector<std::string>{"a"}));
  EXPECT_EQ(layers.Effective("a"), base);
  EXPECT_TRUE(layers.Pop("never_pushed").empty());
}

TEST(NetemSpec, CommandLineOverrideOfTheMeshBlock) {
  // `--set network.mesh.loss=0.1` edits the YAML tree before parsing; the parser sees the new value.
  yaml::Node doc = Yaml("network:\n  mesh: {delay_ms: 100, jitter_ms: 20, loss: 0.05}\n");
  doc.Find("network")->Find("mesh")->Set("loss", yaml::Node::Scalar("0.1"));
  auto mesh = ParseMeshBlock(*doc.Find("network")->Find("mesh"));
  ASSERT_TRUE(mesh) << mesh.error().ToString();
  EXPECT_EQ(mesh->rules[0].spec.loss, 0.1);
  doc.Find("network")->Find("mesh")->Set("loss", yaml::Node::Scalar("1.5"));
  auto bad = ParseMeshBlock(*doc.Find("network")->Find("mesh"));
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message().find("'loss' is a probability in [0, 1]"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::faults
