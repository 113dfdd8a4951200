#include "bus_echo.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <thread>
#include <vector>

#include "swarmbox/bus/participant.hpp"

namespace swarmbox::bus::testing {
namespace {

template <BusMessage In, BusMessage Out, typename Answer>
Status Serve(Participant& p, const std::string& in_topic, const std::string& out_topic,
             const std::atomic<bool>& stop, Answer answer) {
  auto sub = p.CreateSubscriber<In>(in_topic, Qos::kLockstep);
  if (!sub) return std::move(sub).error().Context("echo subscriber");
  auto pub = p.CreatePublisher<Out>(out_topic, Qos::kLockstep);
  if (!pub) return std::move(pub).error().Context("echo publisher");
  std::fprintf(stderr, "echo ready\n");
  In in;
  Out out;
  while (!stop.load()) {
    if (!(*sub)->TakeFor(in, std::chrono::milliseconds(50))) continue;
    const Out& reply = answer(in, out);
    if (auto s = (*pub)->Publish(reply); !s) return s.error().Context("echo publish");
  }
  return Ok{};
}

// One agent per drone name, all in this process: each answers its SensorSample with an
// ActuatorCommand of the same step from the subscriber's callback (a middleware thread).
Status ServeFleet(Participant& p, int drones, const std::atomic<bool>& stop) {
  struct Agent {
    std::unique_ptr<Publisher<ActuatorCommand>> pub;
    std::unique_ptr<Subscriber<SensorSample>> sub;
    ActuatorCommand cmd;  // only touched by the sub's callback (one call at a time)
  };
  std::vector<std::unique_ptr<Agent>> agents;
  for (int i = 0; i < drones; ++i) {
    const std::string name = "drone_" + std::to_string(i);
    auto agent = std::make_unique<Agent>();
    auto pub = p.CreatePublisher<ActuatorCommand>(kActuatorTopic, Qos::kLockstep);  // one writer per agent
    if (!pub) return std::move(pub).error().Context("fleet echo publisher");
    agent->pub = std::move(*pub);
    Agent* a = agent.get();
    auto sub = p.CreateSubscriber<SensorSample>(
        SensorTopic(name), Qos::kLockstep, [a](const SensorSample& s) {
          a->cmd.drone = s.drone;
          a->cmd.step = s.step;
          a->cmd.sim_time_ns = s.sim_time_ns;
          a->cmd.armed = true;
          a->cmd.motor_throttle.assign(4, 0.5);
          if (auto st = a->pub->Publish(a->cmd); !st) {
            std::fprintf(stderr, "fleet echo: %s\n", st.error().ToString().c_str());
          }
        });
    if (!sub) return std::move(sub).error().Context("fleet echo subscriber");
    agent->sub = std::move(*sub);
    agents.push_back(std::move(agent));
  }
  std::fprintf(stderr, "echo ready\n");
  while (!stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  for (auto& a : agents) a->sub.reset();  // no callback may run while the publishers go away
  return Ok{};
}

}  // namespace

Result<EchoOptions> EchoOptionsFromMap(const std::map<std::string, std::string>& options) {
  EchoOptions o;
  for (const auto& [key, value] : options) {
    if (key == "backend") {
      o.backend = value;
    } else if (key == "domain") {
      char* end = nullptr;
      const long d = std::strtol(value.c_str(), &end, 10);
      if (value.empty() || *end != '\0') {
        return Error(ErrorCode::kInvalidArgument, "echo: --domain wants an integer, got '" + value + "'");
      }
      o.domain_id = static_cast<int>(d);
    } else if (key == "interface") {
      o.interface = value;
    } else if (key == "kind") {
      if (value != "lockstep" && value != "small" && value != "large" && value != "fleet") {
        return Error(ErrorCode::kInvalidArgument,
                     "echo: unknown --kind '" + value + "': accepted are lockstep, small, large, fleet");
      }
      o.kind = value;
    } else if (key == "drone") {
      o.drone = value;
    } else if (key == "drones") {
      char* end = nullptr;
      const long n = std::strtol(value.c_str(), &end, 10);
      if (value.empty() || *end != '\0' || n < 0 || n > 1000) {
        return Error(ErrorCode::kInvalidArgument, "echo: --drones wants 0..1000, got '" + value + "'");
      }
      o.drones = static_cast<int>(n);
    } else if (key != "role") {
      return Error(ErrorCode::kInvalidArgument,
                   "echo: unknown option --" + key +
                       ": accepted are --backend --domain --interface --kind --drone --drones");
    }
  }
  return o;
}

std::vector<std::string> EchoArgs(const EchoOptions& o) {
  return {"--backend=" + o.backend, "--domain=" + std::to_string(o.domain_id),
          "--interface=" + o.interface, "--kind=" + o.kind, "--drone=" + o.drone,
          "--drones=" + std::to_string(o.drones)};
}

Status RunEcho(const EchoOptions& o, const std::atomic<bool>& stop) {
  auto p = Participant::Create({.backend = o.backend, .domain_id = o.domain_id, .interface = o.interface});
  if (!p) return std::move(p).error().Context("echo");
  if (o.kind == "fleet") return ServeFleet(**p, o.drones, stop);
  if (o.kind == "lockstep") {
    return Serve<SensorSample, ActuatorCommand>(
        **p, SensorTopic(o.drone), std::string(kActuatorTopic), stop,
        [](const SensorSample& s, ActuatorCommand& cmd) -> const ActuatorCommand& {
          cmd.drone = s.drone;  // the key of sim/actuator
          cmd.step = s.step;
          cmd.sim_time_ns = s.sim_time_ns;
          cmd.armed = true;
          cmd.motor_throttle.assign(4, 0.5);
          return cmd;
        });
  }
  const std::string ping(kBenchPingTopic);
  const std::string pong(kBenchPongTopic);
  if (o.kind == "small") {
    return Serve<RaftMessage, RaftMessage>(**p, ping, pong, stop,
                                           [](const RaftMessage& m, RaftMessage&) -> const RaftMessage& { return m; });
  }
  return Serve<CameraImage, CameraImage>(**p, ping, pong, stop,
                                         [](const CameraImage& m, CameraImage&) -> const CameraImage& { return m; });
}

}  // namespace swarmbox::bus::testing
