// swarmbox-agent with --radio-model channel (integration): swarmbox-physics hosting the simulated
// radio channel (--radio-model channel, the wifi_5ghz_mesh profile, rtf 0, seed 7) and three
// agents with --members and the link probe, no mesh DDS domain at all. The agents elect one
// leader and commit proposals through the channel, measure their links in simulated ms, and two
// runs of the same trial give byte-identical agent logs up to the end of the simulated run
// (every decision on the lockstep's simulated time; the wall clock feeds none). One DDS domain
// (the sim bus only), an odd one of 101-199 by process id: agent_program_test's mesh domains,
// whose mesh/* topics never meet the sim/* ones.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "support/files.hpp"
#include "support/logged_child.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/radio/link_event.hpp"

namespace swarmbox::agent::testing {
namespace {

using namespace std::chrono_literals;
using swarmbox::testing::LoggedChild;
using swarmbox::testing::MakeTempDir;

const std::vector<std::string> kNames = {"drone_1", "drone_2", "drone_3"};
const std::vector<std::string> kStarts = {"0,0,0", "4,0,0", "0,4,0"};
constexpr double kSimS = 20.0;

int g_run = 0;
int SimDomain() { return 101 + static_cast<int>((getpid() + g_run) % 50) * 2; }

// The lines of `log` whose simulated time is below `until_s`, except those that report wall
// time or the way the process ended.
std::string SimulatedLines(const std::string& log, double until_s) {
  std::istringstream in(log);
  std::string line, out;
  while (std::getline(in, line)) {
    const LogfmtFields f = ParseLogfmt(line);
    const auto t = FindField(f, "t");
    const auto event = FindField(f, "event");
    if (!t || !event || *event == "ready" || *event == "samples_stopped" || *event == "stopped") continue;
    if (std::stod(*t) >= until_s) continue;
    out += line + "\n";
  }
  return out;
}

struct TrialRun {
  std::map<std::string, std::string> logs;
  std::string physics_log;
};

TrialRun RunTrial(const std::string& root) {
  ++g_run;
  TrialRun run;
  std::vector<std::string> argv = {SWARMBOX_PHYSICS_BIN,
                                   "--world",
                                   SWARMBOX_TRIALS_DIR "/worlds/open_field.yaml",
                                   "--rtf",
                                   "0",
                                   "--domain",
                                   std::to_string(SimDomain()),
                                   "--max-sim-time",
                                   std::to_string(kSimS),
                                   "--no-cameras",
                                   "--seed",
                                   "7",
                                   "--truth",
                                   "",
                                   "--radio-model",
                                   "channel",
                                   "--radio-profile",
                                   SWARMBOX_TRIALS_DIR "/radios/wifi_5ghz_mesh.yaml"};
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    argv.push_back("--drone");
    argv.push_back(kNames[i] + ":x500:" + kStarts[i]);
  }
  std::string members;
  for (const std::string& m : kNames) members += (members.empty() ? "" : ",") + m;
  std::vector<std::unique_ptr<LoggedChild>> agents;
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    agents.push_back(std::make_unique<LoggedChild>(
        std::vector<std::string>{SWARMBOX_AGENT_BIN,
                                 "--name",
                                 kNames[i],
                                 "--airframe",
                                 SWARMBOX_TRIALS_DIR "/airframes/x500.yaml",
                                 "--sim-domain",
                                 std::to_string(SimDomain()),
                                 "--radio-model",
                                 "channel",
                                 "--start",
                                 kStarts[i],
                                 "--plan",
                                 "takeoff:3,hover:1000",
                                 "--members",
                                 members,
                                 "--raft-dir",
                                 root + "/run" + std::to_string(g_run) + "_" + kNames[i],
                                 "--seed",
                                 "7",
                                 "--propose-every-ms",
                                 "300",
                                 "--ping-every-ms",
                                 "200",
                                 "--sample-timeout",
                                 "60",
                                 "--stall-timeout",
                                 "3"},
        root + "/run" + std::to_string(g_run) + "_" + kNames[i] + ".log"));
    EXPECT_TRUE(agents.back()->running()) << agents.back()->spawn_error();
  }
  auto physics = std::make_unique<LoggedChild>(argv, root + "/run" + std::to_string(g_run) + "_physics.log");
  EXPECT_TRUE(physics->running()) << physics->spawn_error();
  EXPECT_EQ(physics->Wait(180s), 0) << physics->ReadLog();  // ends at --max-sim-time
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    // The samples stop: each agent notices after its 3 s stall timeout and exits.
    if (agents[i]->Wait(20s) == -1) agents[i]->Terminate();
    (void)agents[i]->Wait(10s);
    run.logs[kNames[i]] = agents[i]->ReadLog();
  }
  run.physics_log = physics->ReadLog();
  return run;
}

TEST(AgentChannel, RaftAndLinksOnTheSimulatedChannelAreReproducible) {
  const std::string root = MakeTempDir("swarmbox_agent_channel_");
  ASSERT_FALSE(root.empty());
  const TrialRun a = RunTrial(root);
  ASSERT_EQ(a.logs.size(), kNames.size());
  std::string leader;
  for (const auto& [name, log] : a.logs) {
    EXPECT_NE(log.find("radio_model=channel"), std::string::npos) << log;
    // One leader, agreed by all, and commits.
    std::string last_leader;
    for (const LogfmtFields& f : [&] {
           std::vector<LogfmtFields> v;
           std::istringstream in(log);
           std::string line;
           while (std::getline(in, line)) {
             LogfmtFields p = ParseLogfmt(line);
             if (FindField(p, "event") == "leader_elected") v.push_back(std::move(p));
           }
           return v;
         }()) {
      last_leader = FindField(f, "leader").value_or("");
    }
    ASSERT_FALSE(last_leader.empty()) << name << "\n" << log;
    if (leader.empty()) leader = last_leader;
    EXPECT_EQ(last_leader, leader) << name;
    EXPECT_NE(log.find("event=mission_state"), std::string::npos) << name << "\n" << log;
    // Links measured on simulated time: answered pings, RTTs of a few simulated ms (a 5 GHz mesh
    // a few metres apart: airtime and one control step each way), nothing lost at this range.
    std::uint64_t sent = 0, received = 0;
    std::istringstream in(log);
    std::string line;
    while (std::getline(in, line)) {
      const auto l = radio::ParseLinkLine(line);
      if (!l) continue;
      sent += l->sent;
      received += l->received;
      if (l->has_rtt) {
        EXPECT_GT(l->rtt_ms_p50, 0.0) << line;
        EXPECT_LT(l->rtt_ms_p50, 50.0) << line;
      }
    }
    EXPECT_GE(sent, 100u) << name;  // 2 peers x 5 pings/s x ~18 s settled
    EXPECT_EQ(received, sent) << name;
  }
  // The same trial again: every agent's simulated-time lines are the same, byte for byte.
  const TrialRun b = RunTrial(root);
  for (const std::string& name : kNames) {
    EXPECT_EQ(SimulatedLines(a.logs.at(name), kSimS - 1.0), SimulatedLines(b.logs.at(name), kSimS - 1.0))
        << name;
  }
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(root);
}

}  // namespace
}  // namespace swarmbox::agent::testing
