// swarmbox_offboard_test_brain: a brain in its own process for agent_brain_test, in C++ on the
// project's bus and the agent's conversions (brain_convert.hpp): it answers every BrainInput on
// offboard/<drone>/input with the BrainOutput of the same sim_time_ns, from a small brain: take
// off to --altitude-m, then fly to --east-m east of where it hovered (a position setpoint) and
// stay. Uses no clock but the input's simulated time. Exits 0 on SIGTERM/SIGINT; the test
// SIGKILLs it mid-flight to see the agent's offboard failsafe.
//
//   swarmbox_offboard_test_brain --drone scout_1 --domain 41 [--altitude-m 5] [--east-m 3]
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "brain_convert.hpp"
#include "swarmbox/bus/participant.hpp"
#include "swarmbox/bus/topics.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

using namespace swarmbox;

class GoEast final : public brain::Brain {
 public:
  GoEast(double altitude_m, double east_m) : altitude_m_(altitude_m), east_m_(east_m) {}
  void Step(const brain::Input& in, brain::Output& out) override {
    for (const brain::FlightEvent& e : in.flight_events) hovering_ = hovering_ || e.name == "hover";
    if (in.self.flight_mode == "idle" && !asked_) {  // on the ground, the estimator ready
      out.commands.push_back(brain::Command::Takeoff(altitude_m_));
      out.status = "test/takeoff";
      asked_ = true;
      return;
    }
    if (hovering_ && !flying_) {
      flying_ = true;
      target_ = {in.self.position_m.x + east_m_, in.self.position_m.y, in.self.position_m.z};
      out.events.push_back({"test_brain_target", {{"x", std::to_string(target_.x)}}});
    }
    if (flying_) {
      out.setpoint.push_back(brain::Setpoint::Position(target_));
      out.status = "test/flying";
    }
  }

 private:
  double altitude_m_, east_m_;
  bool asked_ = false, hovering_ = false, flying_ = false;
  brain::Vec3 target_;
};

}  // namespace

int main(int argc, char** argv) {
  std::string drone;
  int domain = 0;
  double altitude_m = 5.0, east_m = 3.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--drone") drone = argv[i + 1];
    else if (flag == "--domain") domain = std::atoi(argv[i + 1]);
    else if (flag == "--altitude-m") altitude_m = std::atof(argv[i + 1]);
    else if (flag == "--east-m") east_m = std::atof(argv[i + 1]);
    else {
      std::fprintf(stderr, "swarmbox_offboard_test_brain: unknown flag %s\n", argv[i]);
      return 2;
    }
  }
  if (drone.empty()) {
    std::fprintf(stderr, "usage: swarmbox_offboard_test_brain --drone NAME --domain N [--altitude-m A] [--east-m E]\n");
    return 2;
  }
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);
  auto sim = bus::Participant::Create({.backend = "cyclonedds", .domain_id = domain, .interface = "lo"});
  if (!sim) {
    std::fprintf(stderr, "swarmbox_offboard_test_brain: %s\n", sim.error().ToString().c_str());
    return 3;
  }
  auto in_sub = (*sim)->CreateSubscriber<bus::BrainInput>(bus::OffboardInputTopic(drone), bus::Qos::kLockstep);
  auto out_pub = (*sim)->CreatePublisher<bus::BrainOutput>(bus::OffboardOutputTopic(drone), bus::Qos::kLockstep);
  if (!in_sub || !out_pub) {
    std::fprintf(stderr, "swarmbox_offboard_test_brain: cannot join the offboard topics\n");
    return 3;
  }
  std::printf("event=brain_ready drone=%s\n", drone.c_str());
  std::fflush(stdout);
  GoEast brain(altitude_m, east_m);
  bus::BrainInput wire_in;
  bus::BrainOutput wire_out;
  agent::InputBuffers buffers;
  brain::Output out;
  std::int64_t last_t_ns = -1;
  std::uint64_t answered = 0;
  while (g_stop == 0) {
    if (!(*in_sub)->TakeFor(wire_in, std::chrono::milliseconds(50))) continue;
    if (wire_in.sim_time_ns == last_t_ns) {
      // Resent (the agent has had no answer yet: ours may have gone out before its reader
      // matched): the same answer again, the brain is not stepped twice.
      (void)(*out_pub)->Publish(wire_out);
      continue;
    }
    if (wire_in.sim_time_ns < last_t_ns) continue;
    last_t_ns = wire_in.sim_time_ns;
    agent::FromBus(wire_in, &buffers);
    out.Clear();
    brain.Step(buffers.input, out);
    agent::ToBus(out, drone, wire_in.sim_time_ns, &wire_out);
    (void)(*out_pub)->Publish(wire_out);
    if (++answered == 1) {
      std::printf("event=first_answer t_ns=%lld\n", static_cast<long long>(wire_in.sim_time_ns));
      std::fflush(stdout);
    }
  }
  return 0;
}
