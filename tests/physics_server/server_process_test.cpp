// The swarmbox-physics program as a process (argv, no shell): bad input gives
// `file:line:col: message` and exit 2; SIGTERM ends a run cleanly with truth.csv flushed.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/logged_child.hpp"
#include "test_util.hpp"

namespace swarmbox::physics {
namespace {

using namespace std::chrono_literals;
using swarmbox::testing::LoggedChild;

// A log file for one program run of this test process (stdout and stderr).
std::string LogPath(const std::string& name) {
  return ::testing::TempDir() + "server_process_" + std::to_string(::getpid()) + "_" + name + ".log";
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

TEST(ServerProcess, BadWorldFileIsReportedWithPositionAndExitTwo) {
  const std::string world = WriteTemp("bad_world.yaml", "name: w\nwind: {mean_m_s: [1, 2], gusts: 3}\n");
  LoggedChild c({SWARMBOX_PHYSICS_EXE, "--world", world, "--drone", "a:x500:0,0,0", "--airframes-dir",
                 testing::TrialsDir() + "/airframes"},
                LogPath("bad_world"));
  EXPECT_EQ(c.Wait(60s), 2);
  const std::string out = c.ReadLog();
  EXPECT_EQ(out, "swarmbox-physics: " + world + ":2:18: world: 'mean_m_s': expected a list of 3 values\n");
}

// The radio plan and the radio model: bad input is refused before the bus is touched.
TEST(ServerProcess, BadRadioPlanOrRadioModelExitsTwoWithTheReason) {
  const std::vector<std::string> base = {SWARMBOX_PHYSICS_EXE, "--world", testing::WorldPath("open_field"), "--drone",
                                         "a:x500:0,0,0"};
  auto run = [&](std::vector<std::string> extra, const std::string& name) {
    std::vector<std::string> argv = base;
    argv.insert(argv.end(), extra.begin(), extra.end());
    LoggedChild c(argv, LogPath(name));
    EXPECT_EQ(c.Wait(60s), 2) << name;
    return c.ReadLog();
  };
  const std::string plan = WriteTemp("bad_plan.json", "{\"schedule\": [\n  {\"at_s\": 1, \"name\": \"k\", \"kind\": "
                                                     "\"drone_out\", \"mode\": \"kill\", \"targets\": [\"b\"]}]}\n");
  EXPECT_EQ(run({"--radio-plan", plan}, "plan_unknown_drone"),
            "swarmbox-physics: " + plan + ":2:3: entry 'k': unknown drone 'b'\n");
  EXPECT_EQ(run({"--radio-model", "channel"}, "channel_without_profile"),
            "swarmbox-physics: --radio-model channel needs --radio-profile PATH\n");
  const std::string pareto = WriteTemp("pareto_plan.json", "{\"mesh\": {\"delay_ms\": 10, \"jitter_ms\": 5, "
                                                         "\"distribution\": \"pareto\"}}\n");
  const std::string out = run({"--radio-model", "channel", "--radio-profile", testing::TrialsDir() + "/radios/wifi_5ghz_mesh.yaml",
                               "--radio-plan", pareto},
                              "channel_pareto");
  EXPECT_EQ(out.rfind("swarmbox-physics: " + pareto + ": mesh: ", 0), 0u) << out;
  EXPECT_NE(out.find("pareto"), std::string::npos) << out;
}

TEST(ServerProcess, BadAirframeFileIsReportedWithPositionAndExitTwo) {
  // The shipped x500 with one bad value.
  std::ifstream shipped(testing::AirframePath("x500"));
  std::stringstream text;
  text << shipped.rdbuf();
  std::string yaml = text.str();
  const std::size_t at = yaml.find("\nmass_kg: 2.0643");
  ASSERT_NE(at, std::string::npos);
  yaml.replace(at, 16, "\nmass_kg: heavy");
  const int line = static_cast<int>(std::count(yaml.begin(), yaml.begin() + static_cast<long>(at), '\n')) + 2;
  const std::string af = WriteTemp("bad_af.yaml", yaml);
  LoggedChild c({SWARMBOX_PHYSICS_EXE, "--world", testing::WorldPath("open_field"), "--drone", "a:" + af + ":0,0,0"},
                LogPath("bad_airframe"));
  EXPECT_EQ(c.Wait(60s), 2);
  const std::string out = c.ReadLog();
  EXPECT_EQ(out.rfind("swarmbox-physics: " + af + ":" + std::to_string(line) + ":10: airframe: 'mass_kg': ", 0), 0u)
      << out;
}

// A stereo airframe (x500_depth) flies (issue #23): the server starts with it, renders its pairs
// and ends on SIGTERM as with any other drone (the pairs themselves: sim_server_stereo_test.cpp).
TEST(ServerProcess, AStereoAirframeStartsAndStopsOnSigterm) {
  const std::string domain = std::to_string(100 + (::getpid() + 53) % 100);
  LoggedChild c({SWARMBOX_PHYSICS_EXE, "--world", testing::WorldPath("open_field"), "--drone", "a:x500_depth:0,0,0",
                 "--airframes-dir", testing::TrialsDir() + "/airframes", "--domain", domain, "--join-timeout", "0.2",
                 "--step-timeout", "0.2", "--rtf", "1", "--no-cameras"},
                LogPath("stereo_airframe"));
  ASSERT_TRUE(c.WaitForLog("event=ready", 60s)) << c.ReadLog();
  EXPECT_NE(c.ReadLog().find("node=physics event=ready world=open_field drones=1"), std::string::npos) << c.ReadLog();
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  ASSERT_TRUE(c.Signal(SIGTERM));
  EXPECT_EQ(c.Wait(60s), 0) << c.ReadLog();
  const std::string log = c.ReadLog();
  EXPECT_EQ(log.find("stereo depth camera"), std::string::npos) << log;
  EXPECT_NE(log.find("event=stopped reason=signal"), std::string::npos) << log;
}

TEST(ServerProcess, UsageErrorExitsTwo) {
  LoggedChild c({SWARMBOX_PHYSICS_EXE, "--drone", "a:x500:0,0,0"}, LogPath("usage"));
  EXPECT_EQ(c.Wait(60s), 2);
  const std::string out = c.ReadLog();
  EXPECT_NE(out.find("--world is required"), std::string::npos) << out;
}

TEST(ServerProcess, SigtermEndsTheRunWithTruthFlushed) {
  const std::string truth = ::testing::TempDir() + "sigterm_truth.csv";
  const std::string domain = std::to_string(100 + (::getpid() + 37) % 100);
  LoggedChild c({SWARMBOX_PHYSICS_EXE, "--world", testing::WorldPath("open_field"), "--drone", "a:x500:0,0,0",
                 "--truth", truth, "--truth-rate-hz", "100", "--domain", domain, "--join-timeout", "0.2",
                 "--step-timeout", "0.2", "--rtf", "1", "--no-cameras"},
                LogPath("sigterm"));
  ASSERT_TRUE(c.WaitForLog("event=ready", 60s)) << c.ReadLog();
  const std::string ready = c.ReadLog();
  ASSERT_NE(ready.find("node=physics event=ready world=open_field drones=1"), std::string::npos) << ready;
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  ASSERT_TRUE(c.Signal(SIGTERM));
  const int code = c.Wait(60s);
  const std::string log = c.ReadLog();
  const std::string rest = log.substr(log.find("event=ready"));  // what it printed once ready
  EXPECT_EQ(code, 0) << rest;
  EXPECT_NE(rest.find("event=drone_lost a=a"), std::string::npos) << rest;  // no agent answered
  EXPECT_NE(rest.find("event=stopped reason=signal"), std::string::npos) << rest;
  std::ifstream in(truth);
  std::stringstream s;
  s << in.rdbuf();
  const std::string csv = s.str();
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.back(), '\n');  // whole rows only
  EXPECT_GT(std::count(csv.begin(), csv.end(), '\n'), 10);  // ~0.6 s of simulated time at 100 Hz
}

}  // namespace
}  // namespace swarmbox::physics
