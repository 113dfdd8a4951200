// swarmbox-raft-node: one drone's Raft node (RaftService) on the mesh radio, as a program.
// The stand-in until swarmbox-agent hosts RaftService; used by the integration tests
// (tests/agent/mission/) and for trying consensus over a real (netem) radio by hand:
//
//   swarmbox-raft-node --name scout_1 --members scout_1,scout_2,lifter --data-dir /tmp/r1
//       --domain 180 --interface lo --middleware cyclonedds --seed 42 --propose-every-ms 500
//
// Prints the contract events (event=leader_elected, mission_state, victim_confirmed, ...) on
// stdout, `t` = seconds since the program started (no physics here: wall clock stands in for
// simulated time). Runs until SIGTERM/SIGINT (exit 0) or --duration-s; exits 1 when the storage
// fails (event=raft_stopped), 2 on bad usage, 3 when the bus or the storage cannot be opened.
//
// HOSTING RaftService IN swarmbox-agent (a few lines; agent/app/ is the flight engineer's):
//   1. agent/app/CMakeLists.txt: target_link_libraries(swarmbox-agent PRIVATE swarmbox::mission)
//   2. after the agent has its mesh bus::Participant (`mesh`) and a raft::Clock returning the
//      agent's simulated seconds (`sim_clock`, must outlive the service):
//        #include "swarmbox/mission/raft_service.hpp"
//        mission::RaftServiceConfig rc;
//        rc.driver.self = drone_name;  rc.driver.members = all_drone_names;  // same on all drones
//        rc.driver.seed = trial_seed;  rc.data_dir = raft_data_dir;          // e.g. a volume
//        // optional: raft::ReadRaftOptions(trial_raft_mapping, &rc.driver);
//        auto raft = mission::RaftService::Start(rc, *mesh, sim_clock);   // events -> stdout
//        if (!raft) { fprintf(stderr, "%s\n", raft.error().ToString().c_str()); return 3; }
//   3. in the agent's main loop: `if ((*raft)->WaitStopped(0ms)) return 1;` (storage failed);
//      propose with (*raft)->Propose(cmd) from any thread, read (*raft)->mission() for the plan.
//   4. destroy the service before the mesh participant.
#include <csignal>
#include <cstdio>
#include <string>
#include <vector>

#include <chrono>
#include <thread>

#include "swarmbox/bus/participant.hpp"
#include "swarmbox/mission/demo_mission.hpp"
#include "swarmbox/mission/raft_node_options.hpp"
#include "swarmbox/mission/raft_service.hpp"

namespace {

volatile std::sig_atomic_t g_signal = 0;
void OnSignal(int sig) { g_signal = sig; }

// Seconds since construction on the monotonic clock: the `t` of events in this program.
class SinceStartClock final : public swarmbox::raft::Clock {
 public:
  double NowS() const override {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace

int main(int argc, char** argv) {
  using namespace swarmbox;
  using namespace std::chrono;
  std::vector<std::string> args(argv + 1, argv + argc);
  auto opts = mission::ParseRaftNodeArgs(args);
  if (!opts) {
    std::fprintf(stderr, "swarmbox-raft-node: %s\n%s", opts.error().ToString().c_str(),
                 mission::RaftNodeUsage().c_str());
    return 2;
  }
  if (opts->help) {
    std::fputs(mission::RaftNodeUsage().c_str(), stdout);
    return 0;
  }
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);

  auto mesh = bus::Participant::Create(
      {.backend = opts->middleware, .domain_id = opts->domain, .interface = opts->interface});
  if (!mesh) {
    std::fprintf(stderr, "swarmbox-raft-node: mesh bus: %s\n", mesh.error().ToString().c_str());
    return 3;
  }
  SinceStartClock clock;
  mission::RaftServiceConfig cfg;
  cfg.driver = opts->driver;
  cfg.data_dir = opts->data_dir;
  auto service = mission::RaftService::Start(cfg, **mesh, clock);
  if (!service) {
    std::fprintf(stderr, "swarmbox-raft-node: %s\n", service.error().ToString().c_str());
    return 3;
  }
  mission::RaftService& raft = **service;

  const auto start = steady_clock::now();
  const auto propose_every = milliseconds(opts->propose_every_ms);
  auto next_propose = start + propose_every;
  int code = 0;
  while (g_signal == 0) {
    if (raft.WaitStopped(milliseconds(20))) {
      std::fprintf(stderr, "swarmbox-raft-node: stopped: %s\n",
                   raft.health().error().ToString().c_str());
      code = 1;
      break;
    }
    const auto now = steady_clock::now();
    if (opts->duration_s > 0 && now - start >= duration<double>(opts->duration_s)) break;
    if (opts->propose_every_ms > 0 && now >= next_propose) {
      next_propose = now + propose_every;
      if (raft.is_leader()) {
        if (auto cmd = mission::NextDemoCommand(raft.mission(), raft.self())) {
          (void)raft.Propose(*cmd);  // kUnavailable (leadership just lost): the next round retries
        }
      }
    }
  }
  service->reset();
  return code;
}
