// The SAR mission end to end on loopback (issue #7): swarmbox-physics (open field, two victims,
// as fast as possible) and four swarmbox-agent processes with --mission sar (three x500 scouts,
// the x8_heavy lifter with the stretcher on the ground) over Cyclone DDS. The swarm must find
// both victims through its cameras, agree on them through Raft, carry both home and end with
// event=mission_complete inside a bounded simulated time, with no collision or crash.
// Prints the figures: time to first detection, to each confirmation, mission time (sim and wall).
// DDS domains 216-223 (a pair per process id).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/files.hpp"
#include "support/logged_child.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::agent::testing {
namespace {

using namespace std::chrono_literals;
using Child = swarmbox::testing::LoggedChild;
using swarmbox::testing::MakeTempDir;

constexpr double kMaxMissionSimS = 400.0;  // the bound (sar_search's timeout is 600 s)

int DomainBase() { return 216 + static_cast<int>(getpid() % 4) * 2; }

struct Line {
  double t_s = 0;
  LogfmtFields fields;
};

// Every logfmt line of `log` with event=`event` (optionally node=`node`), in order.
std::vector<Line> Events(const std::string& log, const std::string& event, const std::string& node = "") {
  std::vector<Line> out;
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    LogfmtFields f = ParseLogfmt(line);
    if (FindField(f, "event") != event) continue;
    if (!node.empty() && FindField(f, "node") != node) continue;
    const auto t = FindField(f, "t");
    if (!t) continue;
    out.push_back({std::stod(*t), std::move(f)});
  }
  return out;
}

double Field(const Line& l, const char* key) {
  const auto v = FindField(l.fields, key);
  return v ? std::stod(*v) : std::nan("");
}

TEST(AgentSarMission, FourAgentsFindAndRescueBothVictimsThenComplete) {
  const std::string dir = MakeTempDir("swarmbox_sar_it_");
  ASSERT_FALSE(dir.empty());
  const int d = DomainBase();
  const std::string world = SWARMBOX_TRIALS_DIR "/worlds/open_field.yaml";
  struct Drone {
    const char* name;
    const char* airframe;
    const char* start;
    const char* payload;
  };
  const std::vector<Drone> drones = {{"scout_1", "x500", "0,0,0", ""},
                                     {"scout_2", "x500", "3,0,0", ""},
                                     {"scout_3", "x500", "6,0,0", ""},
                                     {"lifter", "x8_heavy", "0,-10,0", "stretcher"}};
  std::vector<std::string> phys = {SWARMBOX_PHYSICS_BIN, "--world", world, "--rtf", "0", "--domain", std::to_string(d),
                                   "--max-sim-time", "600", "--seed", "42", "--truth", dir + "/truth.csv"};
  std::string members;
  for (const Drone& dr : drones) {
    phys.push_back("--drone");
    std::string spec = std::string(dr.name) + ":" + dr.airframe + ":" + dr.start;
    if (*dr.payload != '\0') spec += std::string(":0:") + dr.payload + ":ground";
    phys.push_back(spec);
    members += (members.empty() ? "" : ",") + std::string(dr.name);
  }
  const auto wall_start = std::chrono::steady_clock::now();
  Child physics(phys, dir + "/physics.log");
  ASSERT_GT(physics.pid(), 0);
  std::vector<std::unique_ptr<Child>> agents;
  for (const Drone& dr : drones) {
    std::vector<std::string> argv = {SWARMBOX_AGENT_BIN, "--name", dr.name, "--airframe",
                                     std::string(SWARMBOX_TRIALS_DIR "/airframes/") + dr.airframe + ".yaml",
                                     "--sim-domain", std::to_string(d), "--mesh-domain", std::to_string(d + 1),
                                     "--start", dr.start, "--members", members, "--seed", "42",
                                     "--raft-dir", dir + "/raft_" + dr.name, "--mission", "sar", "--world", world,
                                     "--inference-latency-ms", "40", "--sample-timeout", "60", "--stall-timeout", "20"};
    if (*dr.payload != '\0') {
      argv.push_back("--payload");
      argv.push_back(dr.payload);
    }
    agents.push_back(std::make_unique<Child>(argv, dir + "/" + dr.name + ".log"));
    ASSERT_GT(agents.back()->pid(), 0);
  }
  auto all_logs = [&] {
    std::string s = "---- physics\n" + physics.ReadLog();
    for (std::size_t i = 0; i < agents.size(); ++i) s += std::string("---- ") + drones[i].name + "\n" + agents[i]->ReadLog();
    return s;
  };

  // Until some agent logs mission_complete (or everything stopped, or the wall deadline).
  std::optional<Line> complete;
  const auto deadline = wall_start + 780s;
  while (std::chrono::steady_clock::now() < deadline && physics.Wait(0ms) == -1) {
    for (auto& a : agents) {
      const auto c = Events(a->ReadLog(), "mission_complete");
      if (!c.empty() && (!complete || c.front().t_s < complete->t_s)) complete = c.front();
    }
    if (complete) break;
    bool all_running = true;  // an agent that died (bad config, crash) ends the wait
    for (auto& a : agents) all_running = all_running && a->Wait(0ms) == -1;
    if (!all_running) break;
    std::this_thread::sleep_for(1s);
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  for (auto& a : agents) a->Terminate();
  physics.Terminate();
  for (std::size_t i = 0; i < agents.size(); ++i) EXPECT_EQ(agents[i]->Wait(30s), 0) << drones[i].name;
  physics.Wait(30s);
  const std::string logs = all_logs();
  ASSERT_TRUE(complete.has_value()) << "no event=mission_complete after " << wall_s << " s wall:\n" << logs;
  EXPECT_LT(complete->t_s, kMaxMissionSimS) << logs;
  EXPECT_EQ(FindField(complete->fields, "victims"), "2");
  EXPECT_EQ(FindField(complete->fields, "rescued"), "2");

  // Both victims confirmed through Raft near where they lie (the agents never read them).
  const std::string scout_log = agents[0]->ReadLog();
  const auto confirmed = Events(scout_log, "victim_confirmed", "scout_1");
  ASSERT_EQ(confirmed.size(), 2u) << scout_log;
  const double truth[2][2] = {{35.0, 20.0}, {-42.0, 55.0}};
  for (const auto& v : truth) {
    double best = 1e9;
    for (const Line& c : confirmed) best = std::min(best, std::hypot(Field(c, "x") - v[0], Field(c, "y") - v[1]));
    EXPECT_LT(best, 3.0) << "victim at " << v[0] << "," << v[1] << " confirmed " << best << " m away";
  }
  // The lifter hooked, set down, reloaded and delivered each victim; its load was felt.
  const std::string lifter_log = agents[3]->ReadLog();
  EXPECT_EQ(Events(lifter_log, "victim_delivered").size(), 2u) << lifter_log;
  EXPECT_EQ(Events(lifter_log, "evacuee_loaded").size(), 2u) << lifter_log;
  EXPECT_TRUE(Events(lifter_log, "payload_missing").empty()) << lifter_log;
  const std::string plog = physics.ReadLog();
  EXPECT_GE(Events(plog, "payload_attached").size(), 4u) << plog;
  EXPECT_TRUE(Events(plog, "collision").empty()) << plog;
  EXPECT_TRUE(Events(plog, "crash").empty()) << plog;
  EXPECT_TRUE(Events(plog, "drone_lost").empty()) << plog;

  // The figures.
  double first_detection = 1e9;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto s = Events(agents[i]->ReadLog(), "sighting_reported");
    if (!s.empty()) first_detection = std::min(first_detection, s.front().t_s);
  }
  std::printf("sar_mission first_detection_s=%.1f", first_detection);
  for (const Line& c : confirmed) {
    std::printf(" confirm_%s_s=%.1f", FindField(c.fields, "id").value_or("?").c_str(), c.t_s);
  }
  std::printf(" mission_s=%.1f wall_s=%.1f\n", complete->t_s, wall_s);
  std::fflush(stdout);
  if (HasFailure()) std::fprintf(stderr, "logs in %s\n", dir.c_str());
}

}  // namespace
}  // namespace swarmbox::agent::testing
