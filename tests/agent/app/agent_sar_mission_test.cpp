// The SAR mission end to end on loopback (issue #7): swarmbox-physics (open field, two victims,
// as fast as possible) and four swarmbox-agent processes with --mission sar (three x500 scouts,
// the x8_heavy lifter with the stretcher on the ground) over Cyclone DDS. The swarm must find
// both victims through its cameras, agree on them through Raft, carry both home and end with
// event=mission_complete inside a bounded simulated time, with no collision or crash.
// Prints the figures: time to first detection, to each confirmation, mission time (sim and wall).
// DDS domains 216-223 (a pair per process id). AgentSarMission.OnTheSimulatedChannelFourAgents...
// flies the same mission with --radio-model channel on domains 72-75 (the sim domain only, one per
// process id): ctest runs the two cases at once, and on a shared domain (both cases' process ids
// alike modulo 4) the one's mesh and the other's sim bus met in discovery.
//
// AgentSarMission.AScoutKilledMidSearchHasItsSectorSweptByTheOthers (issue #8): the same swarm,
// one scout (not the leader) SIGKILLed after its first event=sector_progress; the leader must
// notice it (event=member_lost), hand its sector to live scouts through Raft
// (event=sector_reassigned), they sweep it, and the mission still ends with
// event=mission_complete victims=2 rescued=2 within a bounded simulated time. Prints the kill,
// loss, reassignment and completion times. DDS domains 227-232.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/files.hpp"
#include "sar_swarm.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::agent::testing {
namespace {

using namespace std::chrono_literals;
using swarmbox::testing::MakeTempDir;

constexpr double kMaxMissionSimS = 400.0;  // the bound (sar_search's timeout is 600 s)
// With a scout lost mid-search its sector is swept again by others (leader_kill's timeout is 600 s).
constexpr double kMaxFailoverMissionSimS = 500.0;

int DomainBase() { return 216 + static_cast<int>(getpid() % 4) * 2; }
int ChannelDomain() { return 72 + static_cast<int>(getpid() % 4); }

// The open field's SAR swarm: three x500 scouts and the x8_heavy lifter with the stretcher.
const std::vector<Drone> kDrones = {{"scout_1", "x500", "0,0,0", ""},
                                    {"scout_2", "x500", "3,0,0", ""},
                                    {"scout_3", "x500", "6,0,0", ""},
                                    {"lifter", "x8_heavy", "0,-10,0", "stretcher"}};

void ExpectBothVictimsRescued(const char* label, int domain, bool channel) {
  const std::string dir = MakeTempDir("swarmbox_sar_it_");
  ASSERT_FALSE(dir.empty());
  SarSwarm swarm(kDrones, domain, dir, channel);
  ASSERT_TRUE(swarm.started());
  const std::optional<Line> complete = swarm.Run(1s, 780s, nullptr);
  const double wall_s = swarm.wall_s();
  const std::string logs = swarm.AllLogs();
  ASSERT_TRUE(complete.has_value()) << "no event=mission_complete after " << wall_s << " s wall:\n" << logs;
  EXPECT_LT(complete->t_s, kMaxMissionSimS) << logs;
  EXPECT_EQ(FindField(complete->fields, "victims"), "2");
  EXPECT_EQ(FindField(complete->fields, "rescued"), "2");

  // Both victims confirmed through Raft near where they lie (the agents never read them).
  const std::string scout_log = swarm.Log(0);
  const auto confirmed = Events(scout_log, "victim_confirmed", "scout_1");
  ASSERT_EQ(confirmed.size(), 2u) << scout_log;
  const double truth[2][2] = {{35.0, 20.0}, {-42.0, 55.0}};
  for (const auto& v : truth) {
    double best = 1e9;
    for (const Line& c : confirmed) best = std::min(best, std::hypot(Field(c, "x") - v[0], Field(c, "y") - v[1]));
    EXPECT_LT(best, 3.0) << "victim at " << v[0] << "," << v[1] << " confirmed " << best << " m away";
  }
  // The lifter hooked, set down, reloaded and delivered each victim; its load was felt.
  const std::string lifter_log = swarm.Log(3);
  EXPECT_EQ(Events(lifter_log, "victim_delivered").size(), 2u) << lifter_log;
  EXPECT_EQ(Events(lifter_log, "evacuee_loaded").size(), 2u) << lifter_log;
  EXPECT_TRUE(Events(lifter_log, "payload_missing").empty()) << lifter_log;
  const std::string plog = swarm.PhysicsLog();
  EXPECT_GE(Events(plog, "payload_attached").size(), 4u) << plog;
  EXPECT_TRUE(Events(plog, "collision").empty()) << plog;
  EXPECT_TRUE(Events(plog, "crash").empty()) << plog;
  EXPECT_TRUE(Events(plog, "drone_lost").empty()) << plog;

  // The figures.
  double first_detection = 1e9;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto s = Events(swarm.Log(i), "sighting_reported");
    if (!s.empty()) first_detection = std::min(first_detection, s.front().t_s);
  }
  std::printf("%s first_detection_s=%.1f", label, first_detection);
  for (const Line& c : confirmed) {
    std::printf(" confirm_%s_s=%.1f", FindField(c.fields, "id").value_or("?").c_str(), c.t_s);
  }
  std::printf(" mission_s=%.1f wall_s=%.1f\n", complete->t_s, wall_s);
  std::fflush(stdout);
  if (::testing::Test::HasFailure()) std::fprintf(stderr, "logs in %s\n", dir.c_str());
}

TEST(AgentSarMission, FourAgentsFindAndRescueBothVictimsThenComplete) {
  ExpectBothVictimsRescued("sar_mission", DomainBase(), false);
}

// The same mission with --radio-model channel: every mesh frame through the physics server's
// simulated channel, every decision on simulated time (the sim domain only, 72-75: see the top).
TEST(AgentSarMission, OnTheSimulatedChannelFourAgentsRescueBothVictims) {
  ExpectBothVictimsRescued("sar_mission_channel", ChannelDomain(), true);
}


// The agents' Raft leader: the latest event=leader_elected in `log` ("" before any).
std::string LeaderIn(const std::string& log) {
  const auto e = Events(log, "leader_elected");
  return e.empty() ? "" : FindField(e.back().fields, "leader").value_or("");
}

TEST(AgentSarMission, AScoutKilledMidSearchHasItsSectorSweptByTheOthers) {
  const std::string dir = MakeTempDir("swarmbox_sar_failover_it_");
  ASSERT_FALSE(dir.empty());
  SarSwarm swarm(kDrones, 227 + static_cast<int>(getpid() % 3) * 2, dir);
  ASSERT_TRUE(swarm.started());
  // The first scout other than the leader to finish a lane is killed at once (polls every 0.1 s
  // of wall time: about half a second of simulated time at rtf 0 here).
  std::size_t victim = swarm.size();
  double progress_s = -1;
  const auto kill_after_progress = [&] {
    if (victim != swarm.size()) return;
    const std::string leader = LeaderIn(swarm.Log(3));
    for (std::size_t i = 0; i < 3; ++i) {
      const auto p = Events(swarm.Log(i), "sector_progress");
      if (p.empty() || leader.empty() || leader == swarm.drone(i).name) continue;
      victim = i;
      progress_s = p.front().t_s;
      swarm.Kill(i);
      return;
    }
  };
  const std::optional<Line> complete = swarm.Run(100ms, 780s, kill_after_progress);
  const std::string logs = swarm.AllLogs();
  ASSERT_LT(victim, swarm.size()) << "no scout was killed:\n" << logs;
  const std::string killed = swarm.drone(victim).name;
  ASSERT_TRUE(complete.has_value()) << "no event=mission_complete after " << swarm.wall_s() << " s wall:\n" << logs;
  EXPECT_LT(complete->t_s, kMaxFailoverMissionSimS) << logs;
  EXPECT_EQ(FindField(complete->fields, "victims"), "2");
  EXPECT_EQ(FindField(complete->fields, "rescued"), "2");

  // The leader noticed the loss and handed the sector over; the pieces were taken and swept.
  std::optional<Line> lost, handed;
  for (std::size_t i = 0; i < swarm.size(); ++i) {
    for (const Line& l : Events(swarm.Log(i), "member_lost")) {
      if (FindField(l.fields, "drone") == killed && (!lost || l.t_s < lost->t_s)) lost = l;
    }
    for (const Line& l : Events(swarm.Log(i), "sector_reassigned")) {
      if (FindField(l.fields, "from") == killed && (!handed || l.t_s < handed->t_s)) handed = l;
    }
  }
  ASSERT_TRUE(lost.has_value()) << logs;
  ASSERT_TRUE(handed.has_value()) << logs;
  EXPECT_GE(handed->t_s, lost->t_s);
  const std::string to = FindField(handed->fields, "to").value_or("");
  EXPECT_EQ(to.find(killed), std::string::npos) << to;
  double taken_s = 1e9, swept_s = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    if (i == victim || to.find(swarm.drone(i).name) == std::string::npos) continue;
    const auto started = Events(swarm.Log(i), "sector_started");
    const auto swept = Events(swarm.Log(i), "sector_swept");
    ASSERT_GE(started.size(), 2u) << swarm.drone(i).name << " never started its piece:\n" << swarm.Log(i);
    EXPECT_EQ(swept.size(), started.size()) << swarm.Log(i);  // its own sector and the piece(s)
    taken_s = std::min(taken_s, started[1].t_s);
    if (!swept.empty()) swept_s = std::max(swept_s, swept.back().t_s);
  }
  const std::string plog = swarm.PhysicsLog();
  EXPECT_TRUE(Events(plog, "collision").empty()) << plog;
  std::printf("sar_failover killed=%s progress_s=%.1f lost_s=%.1f silent_s=%s reassigned_s=%.1f to=%s "
              "first_piece_started_s=%.1f last_swept_s=%.1f mission_s=%.1f wall_s=%.1f\n",
              killed.c_str(), progress_s, lost->t_s, FindField(lost->fields, "silent_s").value_or("?").c_str(),
              handed->t_s, to.c_str(), taken_s, swept_s, complete->t_s, swarm.wall_s());
  std::fflush(stdout);
  if (HasFailure()) std::fprintf(stderr, "logs in %s\n", dir.c_str());
}

// Issue 18: the swarm-scale mission logic in real flight, at the size this shared machine allows
// outside containers: twelve x500 scouts on the trial's 4 m take-off grid (4 columns) and the
// lifter, on the simulated channel. One AssignSectors for all twelve (each sector_started once,
// nothing handed over), take-off in waves and the way home in layers without a collision, both
// victims rescued, event=mission_complete. Prints the mission and wall time. DDS domains 56-61 (the
// sim domain only, the channel: the mesh domain passed is never opened; 233+ is out of range).
TEST(AgentSarMission, TwelveScoutsFromTheFourMetreGridOnTheChannelComplete) {
  std::vector<std::string> text;
  text.reserve(2 * 13);  // the Drones point into it: no reallocation
  std::vector<Drone> drones;
  for (int i = 0; i < 12; ++i) {
    text.push_back("scout_" + std::to_string(i + 1));
    text.push_back(std::to_string(4 * (i % 4)) + "," + std::to_string(4 * (i / 4)) + ",0");
    drones.push_back({text[text.size() - 2].c_str(), "x500", text.back().c_str(), ""});
  }
  drones.push_back({"lifter", "x8_heavy", "0,-10,0", "stretcher"});
  const std::string dir = MakeTempDir("swarmbox_sar_grid_it_");
  ASSERT_FALSE(dir.empty());
  SarSwarm swarm(drones, 56 + static_cast<int>(getpid() % 3) * 2, dir, /*channel=*/true);
  ASSERT_TRUE(swarm.started());
  const std::optional<Line> complete = swarm.Run(1s, 1200s, nullptr);
  const std::string logs = swarm.AllLogs();
  ASSERT_TRUE(complete.has_value()) << "no event=mission_complete after " << swarm.wall_s() << " s wall:\n"
                                    << logs;
  EXPECT_LT(complete->t_s, kMaxMissionSimS) << logs;
  EXPECT_EQ(FindField(complete->fields, "rescued"), "2");
  for (std::size_t i = 0; i < 12; ++i) {
    const std::string log = swarm.Log(i);
    EXPECT_EQ(Events(log, "sector_started").size(), 1u) << swarm.drone(i).name << ":\n" << log;
    EXPECT_TRUE(Events(log, "sector_reassigned").empty()) << swarm.drone(i).name;
  }
  const std::string plog = swarm.PhysicsLog();
  EXPECT_TRUE(Events(plog, "collision").empty()) << plog;
  EXPECT_TRUE(Events(plog, "crash").empty()) << plog;
  EXPECT_TRUE(Events(plog, "drone_lost").empty()) << plog;
  std::printf("sar_grid scouts=12 mission_s=%.1f wall_s=%.1f\n", complete->t_s, swarm.wall_s());
  std::fflush(stdout);
  if (::testing::Test::HasFailure()) std::fprintf(stderr, "logs in %s\n", dir.c_str());
}

}  // namespace
}  // namespace swarmbox::agent::testing
