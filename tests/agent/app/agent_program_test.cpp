// swarmbox-agent as a program: its failure without a physics server, and the integration test of
// the issue: swarmbox-physics and three swarmbox-agent processes over the bus on loopback (a
// private DDS domain per run), all take off, hover and land.
#include <gtest/gtest.h>
#include <signal.h>

#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "support/files.hpp"
#include "support/logged_child.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::agent::testing {
namespace {

using namespace std::chrono_literals;
using swarmbox::testing::LoggedChild;
using swarmbox::testing::MakeTempDir;

// A domain pair per process so parallel test runs never share a bus (100-199: 200-215 are
// agent_raft_test's).
int DomainBase() { return 100 + static_cast<int>(getpid() % 50) * 2; }

bool HasEvent(const std::string& log, const std::string& node, const std::string& event) {
  std::size_t start = 0;
  while (start < log.size()) {
    std::size_t end = log.find('\n', start);
    if (end == std::string::npos) end = log.size();
    const auto fields = ParseLogfmt(std::string_view(log).substr(start, end - start));
    if (FindField(fields, "node") == node && FindField(fields, "event") == event) return true;
    start = end + 1;
  }
  return false;
}

TEST(AgentProgram, FailsClearlyWhenThePhysicsServerIsAbsent) {
  const std::string dir = MakeTempDir("swarmbox_agent_test_");
  ASSERT_FALSE(dir.empty());
  const int d = DomainBase();
  LoggedChild agent(
      {SWARMBOX_AGENT_BIN, "--name", "drone_7", "--airframe", SWARMBOX_TRIALS_DIR "/airframes/x500.yaml",
       "--sim-domain", std::to_string(d), "--mesh-domain", std::to_string(d + 1), "--sample-timeout", "1"},
      dir + "/agent.log");
  ASSERT_GT(agent.pid(), 0);
  EXPECT_EQ(agent.Wait(20s), 3);  // infrastructure error
  const std::string log = agent.ReadLog();
  EXPECT_TRUE(HasEvent(log, "drone_7", "ready")) << log;
  EXPECT_NE(log.find("no sensor sample on sim/drone_7/sensor"), std::string::npos) << log;
  EXPECT_NE(log.find("swarmbox-physics running"), std::string::npos) << log;
}

TEST(AgentProgram, RejectsABadPlanWithUsageExitCode) {
  const std::string dir = MakeTempDir("swarmbox_agent_test_");
  LoggedChild agent({SWARMBOX_AGENT_BIN, "--name", "drone_7", "--airframe",
                     SWARMBOX_TRIALS_DIR "/airframes/x500.yaml", "--plan", "takeoff:5,fly_away"},
                    dir + "/agent.log");
  EXPECT_EQ(agent.Wait(20s), 2);
  EXPECT_NE(agent.ReadLog().find("unknown step 'fly_away'"), std::string::npos) << agent.ReadLog();
}

TEST(AgentIntegration, PhysicsAndThreeAgentsTakeOffHoverAndLand) {
  const std::string dir = MakeTempDir("swarmbox_agent_it_");
  ASSERT_FALSE(dir.empty());
  const int d = DomainBase();
  const std::vector<std::string> names = {"drone_1", "drone_2", "drone_3"};
  const std::vector<std::string> starts = {"0,0,0", "4,0,0", "0,4,0"};
  std::vector<std::string> phys_args = {SWARMBOX_PHYSICS_BIN, "--world", SWARMBOX_TRIALS_DIR "/worlds/open_field.yaml",
                                        "--rtf", "0", "--domain", std::to_string(d), "--max-sim-time", "40",
                                        "--no-cameras", "--seed", "7", "--truth", dir + "/truth.csv"};
  for (std::size_t i = 0; i < names.size(); ++i) {
    phys_args.push_back("--drone");
    phys_args.push_back(names[i] + ":x500:" + starts[i]);
  }
  LoggedChild physics(phys_args, dir + "/physics.log");
  ASSERT_GT(physics.pid(), 0);
  std::vector<std::unique_ptr<LoggedChild>> agents;
  for (std::size_t i = 0; i < names.size(); ++i) {
    agents.push_back(std::make_unique<LoggedChild>(
        std::vector<std::string>{SWARMBOX_AGENT_BIN, "--name", names[i], "--airframe",
                                 SWARMBOX_TRIALS_DIR "/airframes/x500.yaml", "--sim-domain", std::to_string(d),
                                 "--mesh-domain", std::to_string(d + 1), "--start", starts[i], "--plan",
                                 "takeoff:4,hover:4,land", "--stall-timeout", "3", "--sample-timeout", "30"},
        dir + "/" + names[i] + ".log"));
    ASSERT_GT(agents.back()->pid(), 0);
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    const int code = agents[i]->Wait(150s);
    const std::string log = agents[i]->ReadLog();
    EXPECT_EQ(code, 0) << names[i] << ":\n" << log;
    for (const char* ev : {"ready", "takeoff", "hover", "landed", "plan_complete"}) {
      EXPECT_TRUE(HasEvent(log, names[i], ev)) << names[i] << " missing event=" << ev << ":\n" << log;
    }
  }
  EXPECT_EQ(physics.Wait(30s), 0) << physics.ReadLog();
  const std::string plog = physics.ReadLog();
  EXPECT_EQ(plog.find("event=crash"), std::string::npos) << plog;
  EXPECT_EQ(plog.find("event=drone_lost"), std::string::npos) << plog;
}

// SIGSTOP for longer than the stall timeout, then SIGCONT: the agent resumes the lockstep (its
// stall timeout counts time spent waiting, and it looks at the topic once more) and completes
// its plan. The physics server waits for it (--step-timeout 60).
TEST(AgentIntegration, SurvivesASigstopLongerThanItsStallTimeout) {
  const std::string dir = MakeTempDir("swarmbox_agent_it_");
  ASSERT_FALSE(dir.empty());
  const int d = DomainBase();
  LoggedChild physics({SWARMBOX_PHYSICS_BIN, "--world", SWARMBOX_TRIALS_DIR "/worlds/open_field.yaml", "--rtf", "1",
                       "--domain", std::to_string(d), "--max-sim-time", "40", "--no-cameras", "--seed", "7",
                       "--truth", "", "--step-timeout", "60", "--drone", "drone_1:x500:0,0,0"},
                      dir + "/physics.log");
  ASSERT_GT(physics.pid(), 0);
  LoggedChild agent({SWARMBOX_AGENT_BIN, "--name", "drone_1", "--airframe", SWARMBOX_TRIALS_DIR "/airframes/x500.yaml",
                     "--sim-domain", std::to_string(d), "--mesh-domain", std::to_string(d + 1), "--start", "0,0,0",
                     "--plan", "takeoff:3,hover:2,land", "--stall-timeout", "2", "--sample-timeout", "30",
                     "--exit-when-done"},
                    dir + "/agent.log");
  ASSERT_GT(agent.pid(), 0);
  ASSERT_TRUE(agent.WaitForLog("event=takeoff", 60s)) << agent.ReadLog();
  ASSERT_TRUE(agent.Signal(SIGSTOP));
  std::this_thread::sleep_for(4s);  // twice the stall timeout
  ASSERT_TRUE(agent.Signal(SIGCONT));
  EXPECT_EQ(agent.Wait(120s), 0) << agent.ReadLog();
  const std::string log = agent.ReadLog();
  EXPECT_TRUE(HasEvent(log, "drone_1", "plan_complete")) << log;
  EXPECT_FALSE(HasEvent(log, "drone_1", "samples_stopped")) << log;
  physics.Terminate();
  (void)physics.Wait(20s);
  EXPECT_EQ(physics.ReadLog().find("event=drone_lost"), std::string::npos) << physics.ReadLog();
}

}  // namespace
}  // namespace swarmbox::agent::testing
