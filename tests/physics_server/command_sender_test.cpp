// `swarmbox-physics --send-command` and SendWorldCommand against a real SimServer on the sim bus
// (DDS on loopback, an in-process fake agent flying drone "a"): the command's effect shows in the
// drone's sensor samples (no GPS fix during a dropout), the server logs it, and the error paths
// (unknown command, wrong arguments, no server) exit with their codes and messages.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "bus_transport.hpp"
#include "command_sender.hpp"
#include "server_thread.hpp"
#include "sim_server.hpp"
#include "support/logged_child.hpp"
#include "test_util.hpp"
#include "world_commands.hpp"

namespace swarmbox::physics {
namespace {

int TestDomain(int offset) { return 140 + static_cast<int>((::getpid() + offset) % 60); }

struct ProcessResult {
  int exit_code = -1;
  std::string output;  // stdout + stderr
};

// Runs the program (argv, no shell) to completion (a hang guard of 60 s: then exit_code -1).
ProcessResult RunProgram(const std::vector<std::string>& args) {
  static std::atomic<int> runs{0};
  const std::string log = ::testing::TempDir() + "send_command_" + std::to_string(::getpid()) + "_" +
                          std::to_string(runs.fetch_add(1)) + ".log";
  ProcessResult r;
  {
    swarmbox::testing::LoggedChild child(args, log);
    EXPECT_GT(child.pid(), 0) << child.spawn_error();
    r.exit_code = child.Wait(std::chrono::seconds(60));
    r.output = child.ReadLog();
  }
  ::unlink(log.c_str());
  return r;
}

std::vector<std::string> SendArgs(int domain, std::vector<std::string> words) {
  std::vector<std::string> a{SWARMBOX_PHYSICS_EXE, "--send-command"};
  a.insert(a.end(), words.begin(), words.end());
  for (std::string s : {"--sim-interface", "lo", "--domain"}) a.push_back(s);
  a.push_back(std::to_string(domain));
  a.push_back("--match-timeout");
  a.push_back("1");
  return a;
}

TEST(WorldCommandTable, ChecksNamesArgumentCountsAndSigns) {
  EXPECT_TRUE(CheckWorldCommand("gps_dropout", true, {3.0}).ok());
  EXPECT_TRUE(CheckWorldCommand("wind_gust", false, {1, 0, -1.5, 5}).ok());
  EXPECT_TRUE(CheckWorldCommand("imu_bias_jump", true, {0.3, 0, 0, 0, 0, -0.02}).ok());
  auto unknown = CheckWorldCommand("teleport", true, {});
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().message(), "not supported by this physics server");
  auto no_drone = CheckWorldCommand("gps_dropout", false, {3.0});
  ASSERT_FALSE(no_drone.ok());
  EXPECT_EQ(no_drone.error().message(), "needs a drone and duration_s > 0");
  EXPECT_FALSE(CheckWorldCommand("gps_dropout", true, {0.0}).ok());
  EXPECT_FALSE(CheckWorldCommand("gps_degrade", true, {3.0, 5.0}).ok());
  EXPECT_FALSE(CheckWorldCommand("wind_gust", false, {1, 0, 0, -5}).ok());
  EXPECT_EQ(FindWorldCommand("imu_bias_jump")->arg_count, 6);
}

TEST(SendWorldCommand, RefusesABadCommandBeforeJoiningTheBus) {
  bus::ParticipantConfig pc;
  pc.domain_id = TestDomain(0);
  pc.interface = "lo";
  auto s = SendWorldCommand(pc, {"a", "gps_degrade", {3.0}}, {});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(s.error().message().find("world command gps_degrade: needs a drone, duration_s, h_acc_m, v_acc_m > 0"),
            std::string::npos)
      << s.error().ToString();
}

TEST(SendCommandProgram, BadInputExitsTwoAndNoServerExitsThree) {
  const int domain = TestDomain(1);
  auto unknown = RunProgram(SendArgs(domain, {"a", "teleport", "1"}));
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
  EXPECT_NE(unknown.output.find("world command teleport: not supported by this physics server"), std::string::npos)
      << unknown.output;
  auto not_number = RunProgram(SendArgs(domain, {"a", "gps_dropout", "three"}));
  EXPECT_EQ(not_number.exit_code, 2) << not_number.output;
  EXPECT_NE(not_number.output.find("argument 1 (three) is not a number"), std::string::npos) << not_number.output;
  auto too_few = RunProgram(SendArgs(domain, {"a"}));
  EXPECT_EQ(too_few.exit_code, 2) << too_few.output;
  auto nobody = RunProgram(SendArgs(domain, {"a", "gps_dropout", "3"}));
  EXPECT_EQ(nobody.exit_code, 3) << nobody.output;
  EXPECT_NE(nobody.output.find("no physics server matched on sim/world_command"), std::string::npos) << nobody.output;
}

// The server runs at rtf 1 with one drone whose fake agent answers every sample and watches its
// GPS; the program sends a 1 s dropout (and a gust with a negative component, for the parser).
TEST(SendCommandProgram, GpsDropoutReachesTheServerAndTheDroneLosesItsFix) {
  const int domain = TestDomain(2);
  auto world = testing::MakeWorld(testing::CalmWorld());
  const Airframe af = testing::LoadShippedAirframe("x500");
  const double u = af.HoverRotorSpeed() / af.motor.max_rot_velocity_rad_s;
  testing::Spawn(*world, testing::MakeSpawn("a", af, Vec3{0, 0, 10}, 0, u));

  bus::ParticipantConfig pc;
  pc.domain_id = domain;
  pc.interface = "lo";
  auto agent = bus::Participant::Create(pc);
  ASSERT_TRUE(agent.ok()) << agent.error().ToString();
  auto sensors = (*agent)->CreateSubscriber<bus::SensorSample>(bus::SensorTopic("a"), bus::Qos::kLockstep);
  auto actuators = (*agent)->CreatePublisher<bus::ActuatorCommand>(bus::kActuatorTopic, bus::Qos::kLockstep);
  ASSERT_TRUE(sensors.ok() && actuators.ok());
  auto transport = BusTransport::Create(pc, {"a"}, {af.gps});
  ASSERT_TRUE(transport.ok()) << transport.error().ToString();
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  SimServerOptions so;
  so.rtf = 1.0;
  so.max_sim_time_s = 8.0;
  so.cameras = false;
  so.lockstep.timeout_ns = 2'000'000'000;
  so.lockstep.join_timeout_ns = 20'000'000'000;
  testing::ServerThread server(*world, **transport, so, out);
  ProcessResult sent, gust;
  std::thread sender([&] {
    sent = RunProgram(SendArgs(domain, {"a", "gps_dropout", "1.0"}));
    gust = RunProgram(SendArgs(domain, {"-", "wind_gust", "1", "0", "-0.5", "0.5"}));
  });

  bus::SensorSample s;
  bus::ActuatorCommand cmd;
  cmd.drone = "a";
  cmd.armed = true;
  cmd.motor_throttle.assign(4, u);
  bool fix_before = false, lost_fix = false, fix_after = false;
  while (!server.done()) {
    if (!(*sensors)->TakeFor(s, std::chrono::milliseconds(5))) continue;
    cmd.step = s.step;
    ASSERT_TRUE((*actuators)->Publish(cmd).ok());
    // First a fix, then none (the dropout), then a fix again.
    const bool fix = s.gps.fix_type == bus::GpsFix::k3d;
    if (!fix_before) {
      fix_before = fix && s.gps.valid;
    } else if (!lost_fix) {
      lost_fix = !fix;
    } else {
      fix_after = fix_after || (fix && s.gps.valid);
    }
  }
  const Status result = server.Join();
  sender.join();
  ASSERT_TRUE(result.ok()) << result.error().ToString();
  EXPECT_EQ(sent.exit_code, 0) << sent.output;
  EXPECT_EQ(gust.exit_code, 0) << gust.output;
  EXPECT_TRUE(fix_before);
  EXPECT_TRUE(lost_fix);   // the dropout reached the drone
  EXPECT_TRUE(fix_after);  // and ended after its 1 s
  const std::string log = testing::ReadAll(out);
  std::fclose(out);
  EXPECT_NE(log.find("event=world_command command=gps_dropout target=a"), std::string::npos) << log;
  EXPECT_NE(log.find("event=world_command command=wind_gust target="), std::string::npos) << log;
  EXPECT_EQ(log.find("world_command_rejected"), std::string::npos) << log;
}

}  // namespace
}  // namespace swarmbox::physics
