// swarmbox-raft-node: one drone's Raft node (RaftService) on the mesh radio, as a program.
// Used by the integration tests (tests/agent/raft_service/) and for trying consensus over a real
// (netem) radio by hand:
//
//   swarmbox-raft-node --name scout_1 --members scout_1,scout_2,lifter --data-dir /tmp/r1
//       --domain 180 --interface lo --middleware cyclonedds --seed 42 --propose-every-ms 500
//
// Prints the contract events (event=leader_elected, mission_state, victim_confirmed, ...) on
// stdout, `t` = seconds since the program started (no physics here: the monotonic clock stands in
// for simulated time, as in the agent's netem radio model). Runs until SIGTERM/SIGINT (exit 0) or
// --duration-s; exits 1 when the storage fails (event=raft_stopped), 2 on bad usage, 3 when the
// bus or the storage cannot be opened.
//
// The loop is what a host of the passive RaftService does on the wall clock: RaftRadio's
// middleware callback pushes payloads into a PayloadInbox; the loop sleeps until the next tick,
// the next proposal or the first arrival (whichever is first), feeds what arrived in arrival
// order, then calls Tick(). A payload is thus handled within microseconds of its arrival, as
// with the former service thread.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <string>
#include <vector>

#include "swarmbox/bus/participant.hpp"
#include "swarmbox/raft_service/demo_mission.hpp"
#include "swarmbox/raft_service/payload_inbox.hpp"
#include "swarmbox/raft_service/raft_node_options.hpp"
#include "swarmbox/raft_service/raft_radio.hpp"
#include "swarmbox/raft_service/raft_service.hpp"

namespace {

volatile std::sig_atomic_t g_signal = 0;
void OnSignal(int sig) { g_signal = sig; }

// Seconds since construction on the monotonic clock: the `t` of events in this program.
class SinceStartClock final : public swarmbox::raft::Clock {
 public:
  double NowS() const override {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  // The steady-clock instant of clock time `t_s`.
  std::chrono::steady_clock::time_point At(double t_s) const {
    return start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                        std::chrono::duration<double>(t_s));
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// Prints "swarmbox-raft-node: <context><error>" and returns `code`.
int Fail(int code, const char* context, const swarmbox::Error& e) {
  std::fprintf(stderr, "swarmbox-raft-node: %s%s\n", context, e.ToString().c_str());
  return code;
}

// The wall-clock loop (see the banner) until a signal, --duration-s, or a storage failure (1).
int RunLoop(swarmbox::raft_service::RaftService& raft, swarmbox::raft_service::PayloadInbox& inbox,
            const SinceStartClock& clock, const swarmbox::raft_service::RaftNodeOptions& opts) {
  using namespace swarmbox;
  using namespace std::chrono;
  const auto start = steady_clock::now();
  const auto propose_every = milliseconds(opts.propose_every_ms);
  auto next_propose = start + propose_every;
  std::vector<raft::Bytes> batch;
  while (g_signal == 0) {
    // Wake for the next tick, the next proposal, the first arrival, or at least every 20 ms (a
    // signal or the duration ending).
    auto wake = std::min(clock.At(raft.next_tick_s()), steady_clock::now() + milliseconds(20));
    if (opts.propose_every_ms > 0) wake = std::min(wake, next_propose);
    inbox.WaitUntil(wake);
    batch.clear();
    inbox.Drain(&batch);
    for (const raft::Bytes& b : batch) raft.OnPayload(b);
    (void)raft.Tick();
    const auto now = steady_clock::now();
    if (opts.propose_every_ms > 0 && now >= next_propose && !raft.stopped()) {
      next_propose = now + propose_every;
      if (raft.is_leader()) {
        if (auto cmd = raft_service::NextDemoCommand(raft.mission(), raft.self())) {
          (void)raft.Propose(*cmd);  // kUnavailable (leadership just lost): the next round retries
        }
      }
    }
    if (Status h = raft.health(); !h) return Fail(1, "stopped: ", h.error());
    if (opts.duration_s > 0 && now - start >= duration<double>(opts.duration_s)) break;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace swarmbox;
  std::vector<std::string> args(argv + 1, argv + argc);
  auto opts = raft_service::ParseRaftNodeArgs(args);
  if (!opts) {
    std::fprintf(stderr, "swarmbox-raft-node: %s\n%s", opts.error().ToString().c_str(),
                 raft_service::RaftNodeUsage().c_str());
    return 2;
  }
  if (opts->help) {
    std::fputs(raft_service::RaftNodeUsage().c_str(), stdout);
    return 0;
  }
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);

  auto mesh = bus::Participant::Create(
      {.backend = opts->middleware, .domain_id = opts->domain, .interface = opts->interface});
  if (!mesh) return Fail(3, "mesh bus: ", mesh.error());
  SinceStartClock clock;
  raft_service::PayloadInbox inbox;  // before the radio: its callback pushes here until it is gone
  // A writer per member (RaftRadio: reordering on the radio must not become extra loss).
  auto radio = raft_service::RaftRadio::Create(**mesh, opts->driver.self, opts->driver.members,
                                          [&inbox](std::span<const std::uint8_t> b) { inbox.Push(b); });
  if (!radio) return Fail(3, "", radio.error());
  raft_service::RaftServiceConfig cfg;
  cfg.driver = opts->driver;
  cfg.driver.tap_committed = false;  // the demo reads the mission's state, never the entries
  cfg.data_dir = opts->data_dir;
  auto service = raft_service::RaftService::Start(cfg, **radio, clock);
  if (!service) return Fail(3, "", service.error());
  const int code = RunLoop(**service, inbox, clock, *opts);
  service->reset();
  radio->reset();  // no callback into the inbox after this
  return code;
}
