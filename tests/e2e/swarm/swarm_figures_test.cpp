// The swarm figures from a hand-written trial folder's lines: each definition of swarm_figures.hpp
// on numbers worked out by hand.
#include "swarm_figures.hpp"

#include <gtest/gtest.h>

namespace swarmbox::swarm {
namespace {

const std::vector<std::string> kDrones = {"scout_1", "scout_2", "lifter"};

const std::vector<std::string> kEvents = {
    R"({"wall_s":0.1,"component":"orchestrator","event":"build","target":"sim","outcome":"success"})",
    R"({"wall_s":2.0,"component":"physics","t":0.000,"node":"physics","event":"ready","drones":3})",
    R"({"wall_s":3.0,"component":"scout_1","t":0.000,"node":"scout_1","event":"ready"})",
    R"({"wall_s":3.2,"component":"scout_2","t":0.000,"node":"scout_2","event":"ready"})",
    R"({"wall_s":3.9,"component":"physics","t":0.000,"node":"physics","event":"joining","joined":2,"expected":3})",
    R"({"wall_s":4.1,"component":"lifter","t":0.000,"node":"lifter","event":"ready"})",
    R"({"wall_s":5.5,"component":"scout_1","t":1.000,"node":"scout_1","event":"flight_ready"})",
    R"({"wall_s":10.0,"component":"physics","t":10.000,"node":"physics","event":"clock","rtf":1.0,"lost":0})",
    R"({"wall_s":10.0,"component":"physics","t":10.000,"node":"physics","event":"channel","sent":300})",
    R"({"wall_s":20.0,"component":"physics","t":20.000,"node":"physics","event":"clock","rtf":1.0,"lost":1})",
    R"({"wall_s":20.0,"component":"physics","t":20.000,"node":"physics","event":"channel","sent":660})",
    R"({"wall_s":21.0,"component":"orchestrator","event":"stop","target":"scout_1","outcome":"success"})",
    R"({"wall_s":22.0,"component":"orchestrator","event":"stop","target":"physics","outcome":"success"})",
};

TEST(SwarmFigures, EachFigureAsDefined) {
  TrialSummary r;
  r.outcome = "success";
  r.ending_line = "t=20.000 node=lifter event=mission_complete";
  r.wall_s = 24.0;
  r.sim_s = 20.0;
  r.rtf_achieved = 1.1;
  r.mission_time_s = 19.5;
  CgroupSamples samples = {
      {3.0,
       {{"physics", {1.0, 50, 50}}, {"scout_1", {0.2, 8, 9}}, {"scout_2", {0.3, 9, 9}}, {"lifter", {0.1, 10, 10}}}},
      {10.0,
       {{"physics", {2.0, 55, 60}}, {"scout_1", {0.4, 8, 10}}, {"scout_2", {0.5, 9, 9}}, {"lifter", {0.2, 10, 10}}}},
      {20.0,
       {{"physics", {4.0, 60, 70}},
        {"scout_1", {0.6, 9, 12}},
        {"scout_2", {0.8, 10, 10}},
        {"lifter", {0.4, 10, 11}},
        {"scout_1-brain", {9.0, 99, 99}}}},
  };
  const SwarmFigures f = ComputeSwarmFigures(r, kEvents, samples, kDrones);
  EXPECT_EQ(f.drones, 3);
  EXPECT_EQ(*f.rtf, 1.1);
  EXPECT_DOUBLE_EQ(f.cpu_per_drone, (0.6 + 0.8 + 0.4) / (3 * 20.0));  // not the brain's
  EXPECT_DOUBLE_EQ(f.physics_cpu, 4.0 / 20.0);
  // In flight: the samples at wall 10 (the first at or after start_s 5.5) and 20 (the last before
  // the first stop at 21), 10 simulated s apart (the clock lines at wall 10 and 20).
  EXPECT_DOUBLE_EQ(*f.flying_cpu_per_drone, ((0.6 + 0.8 + 0.4) - (0.4 + 0.5 + 0.2)) / (3 * 10.0));
  EXPECT_DOUBLE_EQ(*f.start_cpu_per_agent_s, (0.4 + 0.5 + 0.2) / 3);
  EXPECT_DOUBLE_EQ(f.mem_per_agent_mib, (12 + 10 + 11) / 3.0);
  EXPECT_DOUBLE_EQ(f.mem_agent_max_mib, 12);
  EXPECT_DOUBLE_EQ(f.mem_total_mib, 60 + 9 + 10 + 10 + 99);
  EXPECT_TRUE(f.mission_complete);
  EXPECT_EQ(*f.mission_s, 19.5);
  EXPECT_DOUBLE_EQ(f.msgs_per_drone_s, 660.0 / 20.0 / 3);
  EXPECT_EQ(f.lost, 1);  // the lockstep's last count
  EXPECT_EQ(f.joined, 3);
  EXPECT_EQ(*f.start_s, 5.5);  // the first line with t > 0, not the joining line at t = 0
  EXPECT_DOUBLE_EQ(f.exit_s, 24.0 - 21.0);
  EXPECT_EQ(FormatSwarmLine(f, 2),
            "drones=2 agents=3 rtf=1.10 cpu_per_drone=0.0300 mem_per_agent_mib=11.0 mission_complete=1 "
            "mission_s=19.5 msgs_per_drone_s=11.0 lost=1 start_s=5.5 exit_s=3.0 joined=3 physics_cpu=0.200 "
            "flying_cpu_per_drone=0.0233 start_cpu_per_agent_s=0.37 mem_agent_max_mib=12.0 mem_total_mib=188 "
            "sim_s=20.0 wall_s=24.0 outcome=success");
}

TEST(SwarmFigures, NoFlyingFigureWithoutTwoSamplesOfEveryDroneInFlight) {
  TrialSummary r;
  r.sim_s = 20.0;
  // Before the start only, then in flight but without the lifter: neither figure.
  CgroupSamples samples = {
      {3.0, {{"scout_1", {0.2, 8, 9}}, {"scout_2", {0.3, 9, 9}}, {"lifter", {0.1, 10, 10}}}},
      {12.0, {{"scout_1", {0.5, 8, 9}}, {"scout_2", {0.6, 9, 9}}}},
  };
  SwarmFigures f = ComputeSwarmFigures(r, kEvents, samples, kDrones);
  EXPECT_FALSE(f.flying_cpu_per_drone);
  EXPECT_FALSE(f.start_cpu_per_agent_s);
  EXPECT_NE(FormatSwarmLine(f, 2).find(" flying_cpu_per_drone=- start_cpu_per_agent_s=- "),
            std::string::npos);
  // One sample of every drone in flight: the start figure, no rate.
  samples.push_back({15.0, {{"scout_1", {0.6, 8, 9}}, {"scout_2", {0.7, 9, 9}}, {"lifter", {0.5, 10, 10}}}});
  f = ComputeSwarmFigures(r, kEvents, samples, kDrones);
  EXPECT_FALSE(f.flying_cpu_per_drone);
  EXPECT_DOUBLE_EQ(*f.start_cpu_per_agent_s, (0.6 + 0.7 + 0.5) / 3);
}

TEST(SwarmFigures, ATimeoutIsNoMissionAndFailedAgentsCountAsLost) {
  TrialSummary r;
  r.outcome = "timeout";
  r.sim_s = 20.0;
  r.mission_time_s = std::nullopt;
  r.failed_agents = 2;
  const SwarmFigures f = ComputeSwarmFigures(r, {kEvents.begin(), kEvents.begin() + 4}, {}, kDrones);
  EXPECT_FALSE(f.mission_complete);
  EXPECT_FALSE(f.mission_s);
  EXPECT_EQ(f.lost, 2);
  EXPECT_EQ(f.joined, 2);
  EXPECT_FALSE(f.start_s);
  EXPECT_EQ(f.cpu_per_drone, 0);
  EXPECT_NE(FormatSwarmLine(f, 2).find(" rtf=- "), std::string::npos);
  EXPECT_NE(FormatSwarmLine(f, 2).find(" mission_complete=0 mission_s=- "), std::string::npos);
}

TEST(SwarmFigures, ParsesResultJson) {
  const TrialSummary s = ParseResultJson(
      R"({"trial":"swarm-100","outcome":"success","reason":"x","wall_s":83.9,"sim_s":60,"metrics":{"mission_time_s":57.25},)"
      R"("ending_line":"t=57.250 node=lifter event=mission_complete","components":[{"name":"lifter","exit_code":0,)"
      R"("oom_killed":false},{"name":"physics","exit_code":3,"oom_killed":false},{"name":"scout_1","exit_code":3,)"
      R"("oom_killed":false},{"name":"scout_2","exit_code":0,"oom_killed":true}],"provenance":{"rtf_achieved":0.813389}})");
  EXPECT_EQ(s.outcome, "success");
  EXPECT_EQ(s.ending_line, "t=57.250 node=lifter event=mission_complete");
  EXPECT_DOUBLE_EQ(s.wall_s, 83.9);
  EXPECT_DOUBLE_EQ(s.sim_s, 60);
  EXPECT_DOUBLE_EQ(*s.rtf_achieved, 0.813389);
  EXPECT_DOUBLE_EQ(*s.mission_time_s, 57.25);
  EXPECT_EQ(s.failed_agents, 2);  // scout_1's exit and scout_2's OOM kill; the physics server is not an agent
  EXPECT_FALSE(ParseResultJson(R"({"metrics":{"mission_time_s":null},"provenance":{"rtf_achieved":null}})").mission_time_s);
}

}  // namespace
}  // namespace swarmbox::swarm
