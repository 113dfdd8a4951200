// The component tree: run priority, downward Build/Run/Stop, upward Shutdown/Restart, module
// states. Lifecycle scenarios are data: a tree, the steps that fail, and the exact side effects.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "swarmbox/dsl/component.hpp"
#include "swarmbox/dsl/network.hpp"
#include "swarmbox/dsl/plugin.hpp"
#include "swarmbox/dsl/trial.hpp"

namespace swarmbox::dsl {
namespace {

using ::testing::ElementsAre;
using ::testing::ElementsAreArray;

// Records every side effect as "<step> <id>"; a step listed in `fail` returns an error.
class FakeEngine : public Engine {
 public:
  std::vector<std::string> log;
  std::vector<std::string> trace;
  std::map<std::string, Verdict> fail;  // "start scout_1" -> verdict

  Verdict CreateNetwork(Network& n) override { return Do("create-network", n); }
  Verdict RemoveNetwork(Network& n) override { return Do("remove-network", n); }
  Verdict CreateContainer(Plugin& p) override { return Do("create", p); }
  Verdict StartContainer(Plugin& p) override { return Do("start", p); }
  Verdict StopContainer(Plugin& p) override { return Do("stop", p); }
  void Trace(const Component& c, EventKind e, const Verdict& v) override {
    trace.push_back(std::string(EventName(e)) + " " + c.id() + " " + std::string(OutcomeName(v.outcome)));
  }

 private:
  Verdict Do(const std::string& step, Component& c) {
    std::string key = step + " " + c.id();
    log.push_back(key);
    auto it = fail.find(key);
    return it == fail.end() ? Verdict::Success() : it->second;
  }
};

// sim, mesh (0), physics (1), scouts (2), recorder (4); the physics server is added after the
// scouts on purpose: order comes from priority, not from insertion.
std::unique_ptr<Trial> MakeTrial() {
  auto trial = std::make_unique<Trial>("t", "r1");
  auto& sim = trial->Add<Network>("sim", NetworkSpec::Subnet("t-r1-sim", "10.77.1.0/24"));
  auto& mesh = trial->Add<Network>("mesh", NetworkSpec::Subnet("t-r1-mesh", "10.77.2.0/24"));
  trial->Add<Plugin>("scout_1", ContainerSpec::Image("agent"), 2).On(sim, "10.77.1.10").On(mesh, "10.77.2.10");
  trial->Add<Plugin>("scout_2", ContainerSpec::Image("agent"), 2).On(sim, "10.77.1.11").On(mesh, "10.77.2.11");
  trial->Add<Plugin>("physics", ContainerSpec::Image("physics"), 1).On(sim, "10.77.1.2");
  trial->Add<Plugin>("recorder", ContainerSpec::Image("recorder"), 4).On(mesh, "10.77.2.3");
  return trial;
}

TEST(Component, RunOrderIsPriorityThenInsertion) {
  auto trial = MakeTrial();
  std::vector<std::string> ids;
  for (Component* c : trial->RunOrder()) ids.push_back(c->id());
  EXPECT_THAT(ids, ElementsAre("sim", "mesh", "physics", "scout_1", "scout_2", "recorder"));
}

TEST(Component, PathJoinsIdsFromTheRoot) {
  Experiment e("exp");
  auto& t = e.Add<Trial>("t1");
  auto& group = t.Add<Component>("drones", 2);
  auto& p = group.Add<Plugin>("scout_1", ContainerSpec());
  EXPECT_EQ(p.Path(), "exp/t1/drones/scout_1");
  EXPECT_EQ(&p.Root(), &e);
  EXPECT_EQ(e.Find("scout_1"), &p);
  EXPECT_EQ(e.Trials().size(), 1u);
}

TEST(Component, PriorityAppliesAtEveryLevel) {
  Trial t("t");
  auto& drones = t.Add<Component>("drones", 2);
  drones.Add<Plugin>("late", ContainerSpec(), 5);
  drones.Add<Plugin>("early", ContainerSpec(), 0);
  t.Add<Plugin>("physics", ContainerSpec(), 1);
  t.Add<Plugin>("faults", ContainerSpec(), 5);
  FakeEngine engine;
  ASSERT_TRUE(t.Start(engine).ok());
  EXPECT_THAT(engine.log, ElementsAre("create physics", "create early", "create late", "create faults",
                                      "start physics", "start early", "start late", "start faults"));
}

struct LifecycleScenario {
  const char* name;
  std::map<std::string, Verdict> fail;
  Outcome start_outcome;
  Outcome stop_outcome;
  std::vector<std::string> effects;  // everything the engine was asked to do, Start then Stop
};

TEST(Component, LifecycleScenarios) {
  const std::vector<LifecycleScenario> scenarios = {
      {"all goes well",
       {},
       Outcome::kSuccess,
       Outcome::kSuccess,
       {"create-network sim", "create-network mesh", "create physics", "create scout_1",
        "create scout_2", "create recorder", "start physics", "start scout_1", "start scout_2",
        "start recorder",
        // Stop: reverse priority, networks last.
        "stop recorder", "stop scout_2", "stop scout_1", "stop physics", "remove-network mesh",
        "remove-network sim"}},
      {"a failed build stops the walk and Stop undoes only what was built",
       {{"create scout_1", Verdict::Err("image missing")}},
       Outcome::kError,
       Outcome::kSuccess,
       {"create-network sim", "create-network mesh", "create physics", "create scout_1",
        "stop physics", "remove-network mesh", "remove-network sim"}},
      {"a failed start stops the walk; the started and the failed one are stopped",
       {{"start physics", Verdict::Fail("not ready: exited with code 3")}},
       Outcome::kFailure,
       Outcome::kSuccess,
       {"create-network sim", "create-network mesh", "create physics", "create scout_1",
        "create scout_2", "create recorder", "start physics", "stop recorder", "stop scout_2",
        "stop scout_1", "stop physics", "remove-network mesh", "remove-network sim"}},
      {"Stop is best effort and reports the worst",
       {{"stop scout_2", Verdict::Err("stop timed out")},
        {"remove-network sim", Verdict::Fail("endpoints left")}},
       Outcome::kSuccess,
       Outcome::kError,
       {"create-network sim", "create-network mesh", "create physics", "create scout_1",
        "create scout_2", "create recorder", "start physics", "start scout_1", "start scout_2",
        "start recorder", "stop recorder", "stop scout_2", "stop scout_1", "stop physics",
        "remove-network mesh", "remove-network sim"}},
      {"a failed network leaves nothing to stop but the other network",
       {{"create-network mesh", Verdict::Err("subnet overlaps")}},
       Outcome::kError,
       Outcome::kSuccess,
       {"create-network sim", "create-network mesh", "remove-network sim"}},
  };
  for (const LifecycleScenario& s : scenarios) {
    SCOPED_TRACE(s.name);
    auto trial = MakeTrial();
    FakeEngine engine;
    engine.fail = s.fail;
    Verdict start = trial->Start(engine);
    EXPECT_EQ(start.outcome, s.start_outcome) << start.ToString();
    Verdict stop = trial->Stop(engine);
    EXPECT_EQ(stop.outcome, s.stop_outcome) << stop.ToString();
    EXPECT_THAT(engine.log, ElementsAreArray(s.effects));
  }
}

TEST(Component, FailedStepCarriesItsSourceAndReason) {
  auto trial = MakeTrial();
  FakeEngine engine;
  engine.fail["create scout_2"] = Verdict::Err("no such image agent");
  Verdict v = trial->Start(engine);
  EXPECT_EQ(v.ToString(), "error: no such image agent (t/scout_2)");
}

TEST(Component, TraceRecordsEveryModuleStep) {
  Trial t("t");
  t.Add<Network>("sim", NetworkSpec());
  t.Add<Plugin>("physics", ContainerSpec(), 1);
  FakeEngine engine;
  engine.fail["start physics"] = Verdict::Fail("exited");
  (void)t.Start(engine);
  (void)t.Stop(engine);
  EXPECT_THAT(engine.trace, ElementsAre("build sim success", "build physics success",
                                        "run sim success", "run physics failure",
                                        "stop physics success", "stop sim success"));
}

TEST(Module, RunWithoutBuildIsAnErrorWithoutSideEffects) {
  Trial t("t");
  auto& p = t.Add<Plugin>("physics", ContainerSpec(), 1);
  FakeEngine engine;
  Verdict v = t.Dispatch(EventKind::kRun, engine);
  EXPECT_EQ(v.outcome, Outcome::kError);
  EXPECT_EQ(v.reason, "cannot run t/physics: it is declared");
  EXPECT_TRUE(engine.log.empty());
  EXPECT_EQ(p.state(), Module::State::kDeclared);
}

TEST(Module, StatesFollowTheLifeCycle) {
  Trial t("t");
  auto& p = t.Add<Plugin>("physics", ContainerSpec(), 1);
  FakeEngine engine;
  EXPECT_EQ(p.state(), Module::State::kDeclared);
  ASSERT_TRUE(t.Dispatch(EventKind::kBuild, engine).ok());
  EXPECT_EQ(p.state(), Module::State::kBuilt);
  ASSERT_TRUE(t.Dispatch(EventKind::kRun, engine).ok());
  EXPECT_EQ(p.state(), Module::State::kRunning);
  ASSERT_TRUE(t.Stop(engine).ok());
  EXPECT_EQ(p.state(), Module::State::kStopped);
  // A second Stop has nothing left to undo.
  ASSERT_TRUE(t.Stop(engine).ok());
  EXPECT_EQ(engine.log.size(), 3u);
}

TEST(Trial, ShutdownPropagatesUpAndTheFirstOneDecides) {
  auto trial = MakeTrial();
  Plugin* scout = trial->FindPlugin("scout_1");
  ASSERT_NE(scout, nullptr);
  EXPECT_TRUE(scout->RaiseShutdown(Verdict::Success()));
  EXPECT_TRUE(trial->FindPlugin("physics")->RaiseShutdown(Verdict::Fail("collision")));
  ASSERT_TRUE(trial->end_verdict().has_value());
  EXPECT_EQ(trial->end_verdict()->outcome, Outcome::kSuccess);
  EXPECT_EQ(trial->end_verdict()->source, "t/scout_1");
}

TEST(Trial, ShutdownOutsideATrialIsNotConsumed) {
  Component root("loose");
  auto& p = root.Add<Plugin>("p", ContainerSpec());
  EXPECT_FALSE(p.RaiseShutdown(Verdict::Fail("x")));
  EXPECT_FALSE(p.RaiseRestart("x"));
}

TEST(Trial, RestartRequestFiresAndRebuildsTheTree) {
  auto trial = MakeTrial();
  FakeEngine engine;
  ASSERT_TRUE(trial->Start(engine).ok());
  trial->FindPlugin("physics")->RaiseShutdown(Verdict::Err("engine hiccup"));
  EXPECT_TRUE(trial->FindPlugin("scout_2")->RaiseRestart("engine hiccup"));
  ASSERT_TRUE(trial->restart_requested());
  EXPECT_EQ(trial->restart_reason(), "engine hiccup (t/scout_2)");
  engine.log.clear();
  Verdict v = trial->Restart(engine);
  EXPECT_TRUE(v.ok()) << v.ToString();
  EXPECT_EQ(trial->restarts(), 1);
  EXPECT_FALSE(trial->restart_requested());
  EXPECT_FALSE(trial->end_verdict().has_value());
  EXPECT_THAT(engine.log,
              ElementsAre("stop recorder", "stop scout_2", "stop scout_1", "stop physics",
                          "remove-network mesh", "remove-network sim", "create-network sim",
                          "create-network mesh", "create physics", "create scout_1",
                          "create scout_2", "create recorder", "start physics", "start scout_1",
                          "start scout_2", "start recorder"));
}

// An engine that runs each level's steps in an order of its own (last first, as a concurrent
// engine may) and records which steps it was handed together.
class LevelEngine : public FakeEngine {
 public:
  std::vector<std::size_t> level_sizes;
  Verdict RunSiblings(const std::vector<std::function<Verdict()>>& steps, bool) override {
    level_sizes.push_back(steps.size());
    Verdict v;
    for (auto it = steps.rbegin(); it != steps.rend(); ++it) v.KeepWorse((*it)());
    return v;
  }
};

TEST(Component, SiblingsOfEqualPriorityGoToTheEngineTogether) {
  auto trial = MakeTrial();
  LevelEngine engine;
  ASSERT_TRUE(trial->Start(engine).ok());
  // Build: {sim, mesh}, {scout_1, scout_2}; Run: the same (physics and recorder are alone).
  EXPECT_THAT(engine.level_sizes, ElementsAre(2u, 2u, 2u, 2u));
  // Levels stay in priority order whatever the engine does inside one.
  EXPECT_THAT(engine.log, ElementsAre("create-network mesh", "create-network sim", "create physics",
                                      "create scout_2", "create scout_1", "create recorder",
                                      "start physics", "start scout_2", "start scout_1",
                                      "start recorder"));
  engine.log.clear();
  engine.level_sizes.clear();
  ASSERT_TRUE(trial->Stop(engine).ok());
  // Stop hands each level over in reverse insertion order (this engine reverses it back).
  EXPECT_THAT(engine.level_sizes, ElementsAre(2u, 2u));
  EXPECT_THAT(engine.log, ElementsAre("stop recorder", "stop scout_1", "stop scout_2",
                                      "stop physics", "remove-network sim", "remove-network mesh"));
}

TEST(Component, AFailureInALevelStopsTheWalkAfterThatLevel) {
  auto trial = MakeTrial();
  LevelEngine engine;  // runs every step of a level, as a concurrent engine does
  engine.fail["create scout_2"] = Verdict::Err("image missing");
  Verdict v = trial->Start(engine);
  EXPECT_EQ(v.ToString(), "error: image missing (t/scout_2)");
  // scout_1 (same level) was created too; the recorder's level never came, nothing started.
  EXPECT_THAT(engine.log, ElementsAre("create-network mesh", "create-network sim", "create physics",
                                      "create scout_2", "create scout_1"));
  engine.log.clear();
  (void)trial->Stop(engine);
  // scout_2 was never built: only scout_1 has something to undo.
  EXPECT_THAT(engine.log, ElementsAre("stop scout_1", "stop physics", "remove-network sim",
                                      "remove-network mesh"));
}

TEST(Trial, EndConditionsAndTimeoutAreKept) {
  Trial t("t");
  t.EndOn("event=mission_complete", Outcome::kSuccess)
      .EndOn("event=collision", Outcome::kFailure, "collision", "physics")
      .SetTimeout(TimeoutPolicy::Sim(Duration::Seconds(60), Duration::Seconds(90)));
  ASSERT_EQ(t.end_conditions().size(), 2u);
  EXPECT_EQ(t.end_conditions()[1].component, "physics");
  EXPECT_EQ(t.timeout().sim.ms(), 60000);
  EXPECT_EQ(t.timeout().outcome, Outcome::kTimeout);
}

}  // namespace
}  // namespace swarmbox::dsl
