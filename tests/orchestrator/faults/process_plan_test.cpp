#include "swarmbox/faults/process_plan.hpp"

#include <gtest/gtest.h>

#include "support/fake_docker_api.hpp"
#include "swarmbox/faults/docker_actions.hpp"
#include "swarmbox/faults/docker_exec_runner.hpp"

namespace swarmbox::faults {
namespace {

using K = DockerAction::Kind;
using swarmbox::testing::FakeDockerApi;

ProcessFault Process(ProcessAction action) {
  ProcessFault f;
  f.action = action;
  return f;
}

TEST(ProcessPlan, KillWithDurationIsUndoneByStart) {
  ProcessFault kill = Process(ProcessAction::kKill);
  kill.signal = "SIGTERM";
  const ProcessPlan plan = PlanProcessFault(kill, {"t1-scout_1", "t1-scout_2"}, /*has_duration=*/true);
  EXPECT_EQ(plan.apply, (std::vector<DockerAction>{{K::kKill, "t1-scout_1", "SIGTERM", 0},
                                                   {K::kKill, "t1-scout_2", "SIGTERM", 0}}));
  EXPECT_EQ(plan.undo, (std::vector<DockerAction>{{K::kStart, "t1-scout_1", "", 0}, {K::kStart, "t1-scout_2", "", 0}}));
}

TEST(ProcessPlan, WithoutDurationNothingIsUndone) {
  EXPECT_TRUE(PlanProcessFault(Process(ProcessAction::kKill), {"c"}, false).undo.empty());
  EXPECT_TRUE(PlanProcessFault(Process(ProcessAction::kPause), {"c"}, false).undo.empty());
}

TEST(ProcessPlan, EachActionAndItsUndo) {
  ProcessFault stop = Process(ProcessAction::kStop);
  stop.timeout_s = 3;
  auto plan = PlanProcessFault(stop, {"c"}, true);
  EXPECT_EQ(plan.apply, (std::vector<DockerAction>{{K::kStop, "c", "", 3}}));
  EXPECT_EQ(plan.undo, (std::vector<DockerAction>{{K::kStart, "c", "", 0}}));
  plan = PlanProcessFault(Process(ProcessAction::kPause), {"c"}, true);
  EXPECT_EQ(plan.apply, (std::vector<DockerAction>{{K::kPause, "c", "", 0}}));
  EXPECT_EQ(plan.undo, (std::vector<DockerAction>{{K::kUnpause, "c", "", 0}}));
  plan = PlanProcessFault(Process(ProcessAction::kRestart), {"c"}, false);
  EXPECT_EQ(plan.apply, (std::vector<DockerAction>{{K::kRestart, "c", "", 10}}));
  EXPECT_TRUE(plan.undo.empty());
}

TEST(ProcessPlan, ExecutesThroughDockerApi) {
  FakeDockerApi api;
  api.AddRunning("a");
  api.AddRunning("b");
  const ProcessPlan plan = PlanProcessFault(Process(ProcessAction::kPause), {"a", "b"}, true);
  ASSERT_TRUE(ExecuteDockerActions(api, plan.apply));
  ASSERT_TRUE(ExecuteDockerActions(api, plan.undo));
  EXPECT_EQ(api.Calls(), (std::vector<std::string>{"pause a", "pause b", "unpause a", "unpause b"}));
}

TEST(ProcessPlan, StopsAtTheFirstFailureAndSaysWhich) {
  FakeDockerApi api;
  for (const char* c : {"a", "b", "c"}) api.AddRunning(c);
  api.fail.insert("kill b SIGKILL");
  const ProcessPlan plan = PlanProcessFault(Process(ProcessAction::kKill), {"a", "b", "c"}, false);
  Status s = ExecuteDockerActions(api, plan.apply);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().message(), "kill b SIGKILL: container is not running");
  EXPECT_EQ(api.Calls(), (std::vector<std::string>{"kill a SIGKILL", "kill b SIGKILL"}));
}

TEST(DockerExecCommandRunner, RunsArgvInTheSidecarAndCollectsOutput) {
  FakeDockerApi api;
  api.AddRunning("t1-scout_1-faults");
  api.exec_answers["tc qdisc replace dev lo root netem delay 0ms"] = {{}, {"Error: Specified qdisc kind is unknown."}, 2};
  DockerExecCommandRunner runner(api, "t1-scout_1-faults");
  auto out = runner.Run({"tc", "qdisc", "replace", "dev", "lo", "root", "netem", "delay", "0ms"});
  ASSERT_TRUE(out) << out.error().ToString();
  EXPECT_EQ(out->exit_code, 2);
  EXPECT_EQ(out->stderr_text, "Error: Specified qdisc kind is unknown.\n");
  EXPECT_EQ(api.Calls(), (std::vector<std::string>{"exec t1-scout_1-faults tc qdisc replace dev lo root netem delay 0ms"}));
}

}  // namespace
}  // namespace swarmbox::faults
