// swarmbox-agent flying brains (integration): swarmbox-physics (rtf 0, the simulated channel) and
//   - three agents with --brain library on the example rendezvous brain (examples/brains,
//     built in this tree as swarmbox_example_rendezvous_brain): they agree on a point through
//     Raft, fly to their slots, land and log rendezvous_complete;
//   - one agent with --brain external driven by swarmbox_offboard_test_brain (a C++ brain
//     process on the offboard topics): it takes off and flies the brain's position setpoint;
//     the brain is SIGKILLed and the agent reports it (brain_unresponsive), holds
//     (offboard_lost), lands (offboard_failsafe) and touches down (landed).
// DDS domains 40-47 (a pair per process id: the library case even, the external case odd).
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "support/files.hpp"
#include "support/logged_child.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::agent::testing {
namespace {

using namespace std::chrono_literals;
using swarmbox::testing::LoggedChild;
using swarmbox::testing::MakeTempDir;

int DomainBase() { return 40 + static_cast<int>(getpid() % 4) * 2; }

// The events of `log`, in order, with their simulated time: "12.340 hover".
std::vector<std::pair<double, std::string>> Events(const std::string& log) {
  std::vector<std::pair<double, std::string>> out;
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    const LogfmtFields f = ParseLogfmt(line);
    const auto t = FindField(f, "t");
    const auto e = FindField(f, "event");
    if (t && e) out.emplace_back(std::stod(*t), *e);
  }
  return out;
}

// Index of the first `event` at or after `from`; -1 when none.
int Find(const std::vector<std::pair<double, std::string>>& events, const std::string& event, int from = 0) {
  for (int i = from; i < static_cast<int>(events.size()); ++i) {
    if (events[static_cast<std::size_t>(i)].second == event) return i;
  }
  return -1;
}

// `step_timeout_s`: the physics server's silence bound; a drone whose agent waits for its external
// brain longer than that is lost (motors off), so it must exceed --brain-wait-ms.
std::vector<std::string> Physics(int domain, double sim_s, const std::vector<std::string>& drones,
                                 double step_timeout_s = 1.0) {
  std::vector<std::string> argv = {SWARMBOX_PHYSICS_BIN, "--world", SWARMBOX_TRIALS_DIR "/worlds/open_field.yaml",
                                   "--rtf", "0", "--domain", std::to_string(domain), "--max-sim-time",
                                   std::to_string(sim_s), "--no-cameras", "--seed", "7", "--truth", "",
                                   "--radio-model", "channel", "--radio-profile",
                                   SWARMBOX_TRIALS_DIR "/radios/wifi_5ghz_mesh.yaml", "--step-timeout",
                                   std::to_string(step_timeout_s)};
  for (const std::string& d : drones) {
    argv.push_back("--drone");
    argv.push_back(d);
  }
  return argv;
}

// A bad --brain combination or library: exit 2 with the reason, before any sample is waited for.
TEST(AgentBrain, RefusesBadBrainsWithUsageExitCode) {
  const std::string dir = MakeTempDir("swarmbox_agent_brain_");
  ASSERT_FALSE(dir.empty());
  const std::vector<std::string> base = {SWARMBOX_AGENT_BIN, "--name", "scout_1", "--airframe",
                                         SWARMBOX_TRIALS_DIR "/airframes/x500.yaml", "--sim-domain",
                                         std::to_string(DomainBase()), "--no-mesh", "--sample-timeout", "1"};
  struct Case {
    std::vector<std::string> args;
    std::string reason;
  };
  const std::vector<Case> cases = {
      {{"--brain", "library", "--brain-library", SWARMBOX_RENDEZVOUS_LIB}, "--brain library needs --brain-name NAME"},
      {{"--brain", "library", "--brain-library", dir + "/nothing.so", "--brain-name", "rendezvous"}, "nothing.so"},
      {{"--brain", "library", "--brain-library", SWARMBOX_RENDEZVOUS_LIB, "--brain-name", "flocking"}, "rendezvous"},
      {{"--brain", "library", "--brain-library", SWARMBOX_RENDEZVOUS_LIB, "--brain-name", "rendezvous", "--brain-args",
        R"({"altitude_m": "high"})"},
       "altitude_m"},
      {{"--brain", "library", "--brain-library", SWARMBOX_RENDEZVOUS_LIB, "--brain-name", "rendezvous", "--brain-args",
        "[1, 2]"},
       "--brain-args"},
      {{"--brain", "external", "--mission", "sar"}, "--mission is for --brain builtin"},
      {{"--brain", "external", "--brain-rate-hz", "60"}, "--brain-rate-hz 60"},
      {{"--brain", "python"}, "expected builtin, library or external"},
  };
  int i = 0;
  for (const Case& c : cases) {
    std::vector<std::string> argv = base;
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    LoggedChild agent(argv, dir + "/case" + std::to_string(i++) + ".log");
    EXPECT_EQ(agent.Wait(30s), 2) << c.reason << "\n" << agent.ReadLog();
    EXPECT_NE(agent.ReadLog().find(c.reason), std::string::npos) << agent.ReadLog();
  }
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

TEST(AgentBrain, LibraryBrainsMeetThroughConsensusAndLand) {
  const std::string dir = MakeTempDir("swarmbox_agent_brain_");
  ASSERT_FALSE(dir.empty());
  const int domain = DomainBase();
  const std::vector<std::string> names = {"scout_1", "scout_2", "scout_3"};
  const std::vector<std::string> starts = {"0,0,0", "6,0,0", "0,6,0"};
  std::vector<std::unique_ptr<LoggedChild>> agents;
  for (std::size_t i = 0; i < names.size(); ++i) {
    agents.push_back(std::make_unique<LoggedChild>(
        std::vector<std::string>{SWARMBOX_AGENT_BIN, "--name", names[i], "--airframe",
                                 SWARMBOX_TRIALS_DIR "/airframes/x500.yaml", "--sim-domain", std::to_string(domain),
                                 "--radio-model", "channel", "--start", starts[i], "--members",
                                 "scout_1,scout_2,scout_3", "--raft-dir", dir + "/raft_" + names[i], "--seed", "7",
                                 "--brain", "library", "--brain-library", SWARMBOX_RENDEZVOUS_LIB, "--brain-name",
                                 "rendezvous", "--brain-args", R"({"altitude_m": 8, "radius_m": 5, "hold_s": 2})",
                                 "--sample-timeout", "60", "--stall-timeout", "3"},
        dir + "/" + names[i] + ".log"));
    ASSERT_TRUE(agents.back()->running()) << agents.back()->spawn_error();
  }
  std::vector<std::string> drones;
  for (std::size_t i = 0; i < names.size(); ++i) drones.push_back(names[i] + ":x500:" + starts[i]);
  LoggedChild physics(Physics(domain, 70.0, drones), dir + "/physics.log");
  ASSERT_TRUE(physics.running()) << physics.spawn_error();
  EXPECT_EQ(physics.Wait(240s), 0) << physics.ReadLog();
  for (std::size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(agents[i]->Wait(30s), 0) << agents[i]->ReadLog();  // samples stopped: a brain's normal end
    const std::string log = agents[i]->ReadLog();
    const auto events = Events(log);
    EXPECT_NE(log.find("event=brain_loaded kind=library name=rendezvous"), std::string::npos) << log;
    const int point = Find(events, "rendezvous_point");
    ASSERT_GE(point, 0) << names[i] << "\n" << log;
    const int landed = Find(events, "landed", point);
    ASSERT_GE(landed, 0) << names[i] << "\n" << log;
    EXPECT_GE(Find(events, "rendezvous_complete", landed), 0) << names[i] << "\n" << log;
    EXPECT_NE(log.find("event=rendezvous_complete members=3"), std::string::npos) << log;
    EXPECT_EQ(log.find("event=offboard_lost"), std::string::npos) << log;  // an in-process brain always answers
  }
  // Every drone computed the same rendezvous point from the same committed log.
  std::string point_line;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string log = agents[i]->ReadLog();
    const auto at = log.find("event=rendezvous_point");
    const std::string p = log.substr(at, log.find('\n', at) - at);
    if (point_line.empty()) point_line = p;
    EXPECT_EQ(p, point_line) << names[i];
  }
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

TEST(AgentBrain, AKilledExternalBrainMakesTheDroneHoldThenLand) {
  const std::string dir = MakeTempDir("swarmbox_agent_brain_");
  ASSERT_FALSE(dir.empty());
  const int domain = DomainBase() + 1;
  LoggedChild agent({SWARMBOX_AGENT_BIN, "--name", "scout_1", "--airframe", SWARMBOX_TRIALS_DIR "/airframes/x500.yaml",
                     "--sim-domain", std::to_string(domain), "--radio-model", "channel", "--start", "0,0,0",
                     "--brain", "external", "--offboard-timeout-ms", "1000", "--offboard-hold-ms", "2000",
                     "--brain-wait-ms", "1000", "--brain-start-ms", "60000", "--sample-timeout", "60",
                     "--stall-timeout", "3"},
                    dir + "/agent.log");
  ASSERT_TRUE(agent.running()) << agent.spawn_error();
  auto brain = std::make_unique<LoggedChild>(
      std::vector<std::string>{SWARMBOX_OFFBOARD_TEST_BRAIN, "--drone", "scout_1", "--domain", std::to_string(domain),
                               "--altitude-m", "5", "--east-m", "3"},
      dir + "/brain.log");
  ASSERT_TRUE(brain->running()) << brain->spawn_error();
  LoggedChild physics(Physics(domain, 40.0, {"scout_1:x500:0,0,0"}, 4.0), dir + "/physics.log");
  ASSERT_TRUE(physics.running()) << physics.spawn_error();
  // The brain flies: take-off, then its position setpoint (arrived), then it dies.
  ASSERT_TRUE(agent.WaitForLog("event=arrived", 120s)) << agent.ReadLog() << brain->ReadLog();
  ASSERT_TRUE(brain->Signal(SIGKILL));
  EXPECT_EQ(brain->Wait(10s), 128 + SIGKILL);
  EXPECT_EQ(physics.Wait(240s), 0) << physics.ReadLog();
  EXPECT_EQ(agent.Wait(30s), 0) << agent.ReadLog();
  const std::string log = agent.ReadLog();
  const auto events = Events(log);
  EXPECT_NE(log.find("event=brain_loaded kind=external"), std::string::npos) << log;
  const int arrived = Find(events, "arrived");
  ASSERT_GE(arrived, 0) << log;
  EXPECT_NE(log.find("event=test_brain_target"), std::string::npos) << log;  // the brain's own event, logged by the agent
  const int unresponsive = Find(events, "brain_unresponsive", arrived);
  const int lost = Find(events, "offboard_lost", arrived);
  ASSERT_GE(unresponsive, 0) << log;
  ASSERT_GE(lost, 0) << log;
  const int failsafe = Find(events, "offboard_failsafe", lost);
  ASSERT_GE(failsafe, 0) << log;
  const int landed = Find(events, "landed", failsafe);
  ASSERT_GE(landed, 0) << log;
  const auto at = [&](int i) { return events[static_cast<std::size_t>(i)].first; };
  // On simulated time: hold 1 s after the last answer, land 2 s after that.
  EXPECT_NEAR(at(failsafe) - at(lost), 2.0, 0.05) << log;
  EXPECT_NE(log.find("action=hold"), std::string::npos) << log;
  EXPECT_NE(log.find("action=land"), std::string::npos) << log;
  EXPECT_EQ(Find(events, "offboard_regained"), -1) << log;
  // The agent kept the lockstep (the physics server never lost it): no crash, a landing.
  const std::string physics_log = physics.ReadLog();
  EXPECT_EQ(physics_log.find("event=drone_lost"), std::string::npos) << physics_log;
  EXPECT_EQ(physics_log.find("event=crash"), std::string::npos) << physics_log;
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace swarmbox::agent::testing
