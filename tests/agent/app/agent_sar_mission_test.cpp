// The SAR mission end to end on loopback (issue #7): swarmbox-physics (open field, two victims,
// as fast as possible) and four swarmbox-agent processes with --mission sar (three x500 scouts,
// the x8_heavy lifter with the stretcher on the ground) over Cyclone DDS. The swarm must find
// both victims through its cameras, agree on them through Raft, carry both home and end with
// event=mission_complete inside a bounded simulated time, with no collision or crash.
// Prints the figures: time to first detection, to each confirmation, mission time (sim and wall).
// DDS domains 216-223 (a pair per process id). AgentSarMission.OnTheSimulatedChannelFourAgents...
// flies the same mission with --radio-model channel (the sim domain only: the pair's second).
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
#include "support/logged_child.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::agent::testing {
namespace {

using namespace std::chrono_literals;
using Child = swarmbox::testing::LoggedChild;
using swarmbox::testing::MakeTempDir;

constexpr double kMaxMissionSimS = 400.0;  // the bound (sar_search's timeout is 600 s)
// With a scout lost mid-search its sector is swept again by others (leader_kill's timeout is 600 s).
constexpr double kMaxFailoverMissionSimS = 500.0;

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

struct Drone {
  const char* name;
  const char* airframe;
  const char* start;
  const char* payload;
};

// The open field's SAR swarm: three x500 scouts and the x8_heavy lifter with the stretcher.
const std::vector<Drone> kDrones = {{"scout_1", "x500", "0,0,0", ""},
                                    {"scout_2", "x500", "3,0,0", ""},
                                    {"scout_3", "x500", "6,0,0", ""},
                                    {"lifter", "x8_heavy", "0,-10,0", "stretcher"}};

// swarmbox-physics (open field, rtf 0, seed 42) and one swarmbox-agent --mission sar per drone,
// on DDS domains `domain` (sim) and `domain` + 1 (mesh); with `channel`, the physics server hosts
// the simulated radio channel (wifi_5ghz_mesh) and there is no mesh domain.
class SarSwarm {
 public:
  SarSwarm(std::vector<Drone> drones, int domain, const std::string& dir, bool channel = false)
      : drones_(std::move(drones)), dir_(dir) {
    const std::string world = SWARMBOX_TRIALS_DIR "/worlds/open_field.yaml";
    std::vector<std::string> phys = {SWARMBOX_PHYSICS_BIN, "--world", world, "--rtf", "0", "--domain",
                                     std::to_string(domain), "--max-sim-time", "600", "--seed", "42",
                                     "--truth", dir + "/truth.csv"};
    if (channel) {
      // As the runner plans a channel trial (runner::kChannelStepTimeoutS): the lost-drone rule is a
      // liveness net, not a judge of an agent the suite's load stalled for a second.
      for (const char* a : {"--radio-model", "channel", "--radio-profile", SWARMBOX_TRIALS_DIR "/radios/wifi_5ghz_mesh.yaml",
                            "--step-timeout", "30"}) {
        phys.push_back(a);
      }
    }
    std::string members;
    for (const Drone& dr : drones_) {
      phys.push_back("--drone");
      std::string spec = std::string(dr.name) + ":" + dr.airframe + ":" + dr.start;
      if (*dr.payload != '\0') spec += std::string(":0:") + dr.payload + ":ground";
      phys.push_back(spec);
      members += (members.empty() ? "" : ",") + std::string(dr.name);
    }
    wall_start_ = std::chrono::steady_clock::now();
    physics_ = std::make_unique<Child>(phys, dir + "/physics.log");
    for (const Drone& dr : drones_) {
      std::vector<std::string> argv = {SWARMBOX_AGENT_BIN, "--name", dr.name, "--airframe",
                                       std::string(SWARMBOX_TRIALS_DIR "/airframes/") + dr.airframe + ".yaml",
                                       "--sim-domain", std::to_string(domain), "--mesh-domain",
                                       std::to_string(domain + 1), "--start", dr.start, "--members", members,
                                       "--seed", "42", "--raft-dir", dir + "/raft_" + dr.name, "--mission", "sar",
                                       "--world", world, "--inference-latency-ms", "40", "--sample-timeout", "60",
                                       "--stall-timeout", "20"};
      if (*dr.payload != '\0') {
        argv.push_back("--payload");
        argv.push_back(dr.payload);
      }
      if (channel) {
        argv.push_back("--radio-model");
        argv.push_back("channel");
      }
      agents_.push_back(std::make_unique<Child>(argv, dir + "/" + dr.name + ".log"));
    }
  }

  bool started() const {
    bool ok = physics_->pid() > 0;
    for (const auto& a : agents_) ok = ok && a->pid() > 0;
    return ok;
  }

  // Polls every `poll` (wall) until some agent logs mission_complete, or an agent not killed
  // here or the physics server has exited, or `wall_limit`; `each_poll` runs at every poll (it
  // may Kill() an agent). Then stops every process. The earliest mission_complete, if any.
  std::optional<Line> Run(std::chrono::milliseconds poll, std::chrono::seconds wall_limit,
                          const std::function<void()>& each_poll) {
    std::optional<Line> complete;
    const auto deadline = wall_start_ + wall_limit;
    while (std::chrono::steady_clock::now() < deadline && physics_->Wait(0ms) == -1) {
      for (auto& a : agents_) {
        const auto c = Events(a->ReadLog(), "mission_complete");
        if (!c.empty() && (!complete || c.front().t_s < complete->t_s)) complete = c.front();
      }
      if (complete) break;
      bool all_running = true;  // an agent that died (bad config, crash) ends the wait
      for (std::size_t i = 0; i < agents_.size(); ++i) {
        all_running = all_running && (i == killed_ || agents_[i]->Wait(0ms) == -1);
      }
      if (!all_running) break;
      if (each_poll) each_poll();
      std::this_thread::sleep_for(poll);
    }
    wall_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
    for (std::size_t i = 0; i < agents_.size(); ++i) {
      if (i != killed_) agents_[i]->Terminate();
    }
    physics_->Terminate();
    for (std::size_t i = 0; i < agents_.size(); ++i) {
      if (i != killed_) {
        EXPECT_EQ(agents_[i]->Wait(30s), 0) << drones_[i].name;
      }
    }
    physics_->Wait(30s);
    return complete;
  }

  // SIGKILL to agent `i` (at most one per run).
  void Kill(std::size_t i) {
    killed_ = i;
    agents_[i]->Signal(SIGKILL);
    EXPECT_EQ(agents_[i]->Wait(10s), 128 + SIGKILL) << drones_[i].name;
  }

  std::size_t size() const { return agents_.size(); }
  const Drone& drone(std::size_t i) const { return drones_[i]; }
  std::string Log(std::size_t i) const { return agents_[i]->ReadLog(); }
  std::string PhysicsLog() const { return physics_->ReadLog(); }
  std::string AllLogs() const {
    std::string s = "---- physics\n" + physics_->ReadLog();
    for (std::size_t i = 0; i < agents_.size(); ++i) s += std::string("---- ") + drones_[i].name + "\n" + agents_[i]->ReadLog();
    return s;
  }
  double wall_s() const { return wall_s_; }
  const std::string& dir() const { return dir_; }

 private:
  std::vector<Drone> drones_;
  std::string dir_;
  std::unique_ptr<Child> physics_;
  std::vector<std::unique_ptr<Child>> agents_;
  std::chrono::steady_clock::time_point wall_start_;
  std::size_t killed_ = static_cast<std::size_t>(-1);
  double wall_s_ = 0;
};

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
// simulated channel, every decision on simulated time (the sim domain only: the first case's
// mesh domain, whose mesh/* topics never meet sim/* ones).
TEST(AgentSarMission, OnTheSimulatedChannelFourAgentsRescueBothVictims) {
  ExpectBothVictimsRescued("sar_mission_channel", DomainBase() + 1, true);
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
