// The bus <-> brain conversions: an Input and an Output survive the trip over the offboard
// messages field for field (NaN stays unset), an unknown command fails with the known names.
#include "brain_convert.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace swarmbox::agent {
namespace {

TEST(BrainConvert, AnInputSurvivesTheOffboardTopic) {
  std::vector<brain::FlightEvent> events = {{"hover", 12, {{"z", "10.00"}}}};
  std::vector<brain::Neighbour> neighbours = {{"a", 5, {1, 2, 3}, {0.5, 0, 0}, 0.25, 0.9, "rv/voting"}};
  std::vector<brain::Message> messages = {{"a", "", "rv/x", {1, 2}}};
  std::vector<brain::Entry> committed = {{4, {'p'}}, {9, {'q'}}};
  std::vector<brain::Detection> detections = {{7, "victim", 0.8, {3, 4, 0}, 1.2}};
  brain::Input in;
  in.t_ns = 20'000'000;
  in.self.name = "b";
  in.self.step = 5;
  in.self.position_m = {1, 2, 3};
  in.self.velocity_m_s = {0.1, 0.2, 0.3};
  const double h = 0.7;  // a yaw-only attitude: the heading comes back from it
  in.self.attitude_wxyz[0] = std::cos(h / 2);
  in.self.attitude_wxyz[3] = std::sin(h / 2);
  in.self.heading_rad = h;
  in.self.angular_rate_rad_s = {0, 0, 0.1};
  in.self.battery_fraction = 0.75;
  in.self.battery_voltage_v = 15.2;
  in.self.flight_mode = "hold";
  in.self.armed = true;
  in.self.landed = false;
  in.self.payload_mass_kg = 2.0;
  in.self.mass_estimate_kg = 4.1;
  in.flight_events = events;
  in.is_leader = true;
  in.leader = "b";
  in.neighbours = neighbours;
  in.messages = messages;
  in.committed = committed;
  in.detections = detections;

  bus::BrainInput wire;
  ToBus(in, "b", &wire);
  EXPECT_EQ(wire.sim_time_ns, 20'000'000);
  EXPECT_EQ(wire.vehicle.sim_time_ns, 20'000'000);
  EXPECT_EQ(wire.neighbours.at(0).mode, "rv/voting");
  EXPECT_EQ(wire.detections.at(0).from, "b");
  InputBuffers back;
  FromBus(wire, &back);
  const brain::Input& r = back.input;
  EXPECT_EQ(r.t_ns, in.t_ns);
  EXPECT_EQ(r.self.name, "b");
  EXPECT_EQ(r.self.step, 5u);
  EXPECT_EQ(r.self.position_m.y, 2.0);
  EXPECT_EQ(r.self.velocity_m_s.z, 0.3);
  EXPECT_NEAR(r.self.heading_rad, h, 1e-12);
  EXPECT_EQ(r.self.battery_voltage_v, 15.2);
  EXPECT_EQ(r.self.flight_mode, "hold");
  EXPECT_TRUE(r.self.armed);
  EXPECT_FALSE(r.self.landed);
  EXPECT_EQ(r.self.payload_mass_kg, 2.0);
  EXPECT_EQ(r.self.mass_estimate_kg, 4.1);
  ASSERT_EQ(r.flight_events.size(), 1u);
  EXPECT_EQ(r.flight_events[0].name, "hover");
  EXPECT_EQ(r.flight_events[0].t_ns, 12);
  EXPECT_EQ(r.flight_events[0].fields.at("z"), "10.00");
  EXPECT_TRUE(r.is_leader);
  EXPECT_EQ(r.leader, "b");
  ASSERT_EQ(r.neighbours.size(), 1u);
  EXPECT_EQ(r.neighbours[0].name, "a");
  EXPECT_EQ(r.neighbours[0].t_ns, 5);
  EXPECT_EQ(r.neighbours[0].status, "rv/voting");
  EXPECT_EQ(r.neighbours[0].battery_fraction, 0.9);
  ASSERT_EQ(r.messages.size(), 1u);
  EXPECT_EQ(r.messages[0].payload, (std::vector<std::uint8_t>{1, 2}));
  ASSERT_EQ(r.committed.size(), 2u);
  EXPECT_EQ(r.committed[1].index, 9u);
  EXPECT_EQ(r.committed[1].data, std::vector<std::uint8_t>{'q'});
  ASSERT_EQ(r.detections.size(), 1u);
  EXPECT_EQ(r.detections[0].sigma_m, 1.2);
  EXPECT_EQ(r.detections[0].position_m.x, 3.0);
}

TEST(BrainConvert, AnOutputSurvivesTheOffboardTopic) {
  brain::Output out;
  brain::Setpoint sp;
  sp.position_m = {1, 2, brain::kUnset};
  sp.velocity_m_s = {brain::kUnset, brain::kUnset, -0.5};
  sp.yawspeed_rad_s = 0.2;
  out.setpoint.push_back(sp);
  out.commands = {brain::Command::Takeoff(10), brain::Command::PayloadAttach(3), brain::Command::Land()};
  out.messages.push_back({"b", "a", "rv/y", {7}});
  out.proposals = {{'x'}, {'y', 'z'}};
  out.status = "rv/flying";
  out.events.push_back({"rendezvous_point", {{"x", "1.0"}, {"y", "2.0"}}});
  bus::BrainOutput wire;
  ToBus(out, "b", 40, &wire);
  EXPECT_EQ(wire.sim_time_ns, 40);
  EXPECT_EQ(wire.commands.at(0).command, "takeoff");
  EXPECT_EQ(wire.commands.at(1).command, "payload_attach");
  brain::Output back;
  ASSERT_TRUE(FromBus(wire, &back));
  ASSERT_EQ(back.setpoint.size(), 1u);
  EXPECT_EQ(back.setpoint[0].position_m.y, 2.0);
  EXPECT_TRUE(std::isnan(back.setpoint[0].position_m.z));
  EXPECT_TRUE(std::isnan(back.setpoint[0].velocity_m_s.x));
  EXPECT_EQ(back.setpoint[0].velocity_m_s.z, -0.5);
  EXPECT_TRUE(std::isnan(back.setpoint[0].yaw_rad));
  EXPECT_EQ(back.setpoint[0].yawspeed_rad_s, 0.2);
  ASSERT_EQ(back.commands.size(), 3u);
  EXPECT_EQ(back.commands[0].kind, brain::Command::Kind::kTakeoff);
  EXPECT_EQ(back.commands[0].param, 10.0);
  EXPECT_EQ(back.commands[1].kind, brain::Command::Kind::kPayloadAttach);
  EXPECT_EQ(back.commands[2].kind, brain::Command::Kind::kLand);
  EXPECT_EQ(back.messages.at(0).to, "a");
  EXPECT_EQ(back.proposals, (std::vector<std::vector<std::uint8_t>>{{'x'}, {'y', 'z'}}));
  EXPECT_EQ(back.status, "rv/flying");
  ASSERT_EQ(back.events.size(), 1u);
  EXPECT_EQ(back.events[0].fields, (std::vector<std::pair<std::string, std::string>>{{"x", "1.0"}, {"y", "2.0"}}));
}

TEST(BrainConvert, RefusesAnUnknownCommandAndTwoSetpoints) {
  bus::BrainOutput wire;
  wire.commands.push_back({"takeoff", 5});
  wire.commands.push_back({"loop_the_loop", 0});
  brain::Output out;
  const Status s = FromBus(wire, &out);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(s.error().ToString().find("unknown command 'loop_the_loop' (known: arm, disarm, takeoff, land, hold, "
                                      "payload_attach, payload_release)"),
            std::string::npos)
      << s.error().ToString();
  bus::BrainOutput two;
  two.setpoint.resize(2);
  const Status t = FromBus(two, &out);
  ASSERT_FALSE(t);
  EXPECT_NE(t.error().ToString().find("at most one setpoint"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::agent
