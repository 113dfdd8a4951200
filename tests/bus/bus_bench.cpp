// `swarmbox-bench bus`: round-trip latency (p50/p99) and throughput of the bus, per backend, for a
// small (~100 B RaftMessage) and a large (320x240 mono8 CameraImage, ~77 KB) message, with the
// echo in the same process (a thread with its own participant) and in a second process (this
// binary re-executed as `swarmbox-bench bus --role=echo ...`, killed on every exit path).
//
// One logfmt line per scenario on stdout:
//   suite=bus scenario=rtt_small backend=cyclonedds mode=two_process payload_bytes=68 n=5000
//   p50_us=.. p99_us=.. max_us=.. timeouts=0 window=8 round_trips_s=.. msgs_s=.. mb_s=..
// Latency: sequential ping-pong (publish, wait for the echo), n round trips after a handshake.
// Throughput: `window` pings in flight; round_trips_s counts completed round trips per second,
// msgs_s = 2 * round_trips_s (each round trip is two messages), mb_s = msgs_s * payload_bytes.
// Options: --quick, --backend=cyclonedds|fastdds|all, --mode=same_process|two_process|all,
//          --size=small|large|all, --domain=<first domain id, default 200>, --n=<round trips>,
//          --interface=<name, default lo>, --echo-backend=<backend of the echo; default: the same>
//          (cross-vendor figures; the line then carries echo_backend=...),
//          --mode=external: no echo is started; one must already run (swarmbox-bus-echo with the
//          same --domain/--kind, e.g. in another network namespace),
//          --scenario=rtt|fleet|lockstep_fleet|agent_step|udp_floor|all (fleet and lockstep_fleet
//          are one scenario; agent_step, paced at 250 Hz, and udp_floor, the same 2N datagrams a
//          step over plain UDP, run only when named),
//          --drones=<fleet size; default 10 (quick) or 10, 50, 100>,
//          --steps=<fleet lockstep steps; default 100 (quick) or 1000>.
// Fleet lines: suite=bus scenario=lockstep_fleet backend=.. drones=N steps=.. step_p50_us=..
//   step_p99_us=.. steps_s=.. msgs_s=.. (2N messages per step) max_hz_per_drone=..
//   cpu_us_per_step=.. (both processes, every thread) server_cpu_us=.. agents_cpu_us=..
//   switches_per_step=.. steps_s_2cores=.. (2 s of CPU per s over cpu_us_per_step: the ceiling on
//   two free cores) timeouts=0
// Agent lines (--scenario=agent_step): suite=bus scenario=agent_step answer=waitset|callback
//   agent_cpu_us_per_step=.. agent_switches_per_step=.. agent_core_fraction=.. (at 250 Hz)
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "bench.hpp"
#include "bus_echo.hpp"
#include "message_samples.hpp"
#include "support/child_process.hpp"
#include "swarmbox/bus/participant.hpp"

namespace swarmbox::bus {
namespace {

using Clock = std::chrono::steady_clock;
using bench::Args;

constexpr std::size_t kSmallPayloadBytes = 68;  // ~100 B on the wire with from/to/term and CDR
constexpr int kWindow = 8;                      // below the kLockstep keep-last depth of 16

std::atomic<bool> g_echo_stop{false};
extern "C" void OnEchoSignal(int) { g_echo_stop.store(true); }

int RunEchoRole(const Args& args) {
  auto o = testing::EchoOptionsFromMap(args.options);
  if (!o) {
    std::fprintf(stderr, "bus echo: %s\n", o.error().ToString().c_str());
    return 2;
  }
  std::signal(SIGTERM, OnEchoSignal);
  std::signal(SIGINT, OnEchoSignal);
  auto s = testing::RunEcho(*o, g_echo_stop);
  if (!s) {
    std::fprintf(stderr, "bus echo: %s\n", s.error().ToString().c_str());
    return 1;
  }
  return 0;
}

// The sequence number a ping carries.
std::uint64_t& Seq(RaftMessage& m) { return m.term; }
std::uint64_t& Seq(CameraImage& m) { return m.step; }

// The echo side of a scenario; stops it on destruction (thread joined / child killed).
class Echo {
 public:
  static std::optional<Echo> Start(const std::string& mode, const testing::EchoOptions& o) {
    Echo e;
    if (mode == "external") return e;  // an echo started by hand (e.g. in another netns)
    if (mode == "same_process") {
      e.stop_ = std::make_unique<std::atomic<bool>>(false);
      e.thread_ = std::thread([o, stop = e.stop_.get()] {
        if (auto s = testing::RunEcho(o, *stop); !s) {
          std::fprintf(stderr, "bus bench: echo thread: %s\n", s.error().ToString().c_str());
        }
      });
      return e;
    }
    std::vector<std::string> argv = {swarmbox::testing::SelfExecutable(), "bus", "--role=echo"};
    for (auto& a : testing::EchoArgs(o)) argv.push_back(a);
    auto child = swarmbox::testing::ChildProcess::Spawn(argv);
    if (!child) {
      std::fprintf(stderr, "bus bench: %s\n", child.error().ToString().c_str());
      return std::nullopt;
    }
    e.child_.emplace(std::move(*child));
    return e;
  }
  Echo() = default;
  Echo(Echo&&) = default;
  Echo& operator=(Echo&&) = delete;
  // The child's pid (two_process), or -1.
  pid_t pid() const { return child_ ? child_->pid() : -1; }
  ~Echo() {
    if (stop_) stop_->store(true);
    if (thread_.joinable()) thread_.join();
    if (child_) child_->Stop(std::chrono::seconds(2));
  }

 private:
  std::unique_ptr<std::atomic<bool>> stop_;
  std::thread thread_;
  std::optional<swarmbox::testing::ChildProcess> child_;
};

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto idx = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(idx, v.size() - 1)];
}

// CPU time of every thread of process `pid` (0: this process) [ns] and its context switches
// (voluntary + involuntary), from /proc/<pid>/task/*/schedstat and status: nanosecond resolution,
// and unlike wall time it holds on a busy host.
struct ProcessUsage {
  std::int64_t cpu_ns = 0;
  std::int64_t switches = 0;
};
ProcessUsage Usage(pid_t pid) {
  ProcessUsage u;
  const std::string dir = pid > 0 ? "/proc/" + std::to_string(pid) + "/task" : std::string("/proc/self/task");
  std::error_code ec;
  for (const auto& task : std::filesystem::directory_iterator(dir, ec)) {
    std::ifstream sched(task.path() / "schedstat");
    std::int64_t run_ns = 0;
    if (sched >> run_ns) u.cpu_ns += run_ns;
    std::ifstream status(task.path() / "status");
    std::string line;
    while (std::getline(status, line)) {
      if (line.rfind("voluntary_ctxt_switches:", 0) == 0 || line.rfind("nonvoluntary_ctxt_switches:", 0) == 0) {
        u.switches += std::strtoll(line.c_str() + line.find(':') + 1, nullptr, 10);
      }
    }
  }
  return u;
}

struct Scenario {
  std::string backend;
  std::string echo_backend;
  std::string mode;
  std::string size;
  std::string interface;
  int domain = 0;
};

template <BusMessage T>
int RunScenario(const Scenario& sc, T ping, std::size_t payload_bytes, int n, int throughput_n) {
  const std::string& backend = sc.backend;
  const std::string& mode = sc.mode;
  const std::string& size = sc.size;
  testing::EchoOptions o{.backend = sc.echo_backend, .domain_id = sc.domain,
                         .interface = sc.interface, .kind = size};
  auto echo = Echo::Start(mode, o);
  if (!echo) return 1;
  auto p = Participant::Create({.backend = backend, .domain_id = sc.domain, .interface = sc.interface});
  if (!p) {
    std::fprintf(stderr, "bus bench: %s\n", p.error().ToString().c_str());
    return 1;
  }
  auto pub = (*p)->CreatePublisher<T>(std::string(testing::kBenchPingTopic), Qos::kLockstep);
  auto sub = (*p)->CreateSubscriber<T>(std::string(testing::kBenchPongTopic), Qos::kLockstep);
  if (!pub || !sub) {
    std::fprintf(stderr, "bus bench: cannot create publisher/subscriber\n");
    return 1;
  }
  const auto match_timeout = std::chrono::milliseconds(15000);
  if (auto s = (*pub)->WaitForSubscribers(1, match_timeout); !s) {
    std::fprintf(stderr, "bus bench: %s\n", s.error().ToString().c_str());
    return 1;
  }
  if (auto s = (*sub)->WaitForPublishers(1, match_timeout); !s) {
    std::fprintf(stderr, "bus bench: %s\n", s.error().ToString().c_str());
    return 1;
  }
  // Handshake (see Publisher::WaitForSubscribers): resend seq 0 until echoed.
  T pong;
  std::uint64_t seq = 0;
  Seq(ping) = seq;
  bool ok = false;
  for (const auto deadline = Clock::now() + match_timeout; !ok && Clock::now() < deadline;) {
    (void)(*pub)->Publish(ping);
    ok = (*sub)->TakeFor(pong, std::chrono::milliseconds(100));
  }
  if (!ok) {
    std::fprintf(stderr, "bus bench: %s/%s/%s: echo never answered\n", backend.c_str(),
                 mode.c_str(), size.c_str());
    return 1;
  }
  while ((*sub)->TakeFor(pong, std::chrono::milliseconds(200))) {
  }  // drain duplicate answers to the handshake

  // Latency: sequential ping-pong.
  std::vector<double> rtt_us;
  rtt_us.reserve(static_cast<std::size_t>(n));
  int timeouts = 0;
  for (int i = 0; i < n; ++i) {
    Seq(ping) = ++seq;
    const auto t0 = Clock::now();
    if (!(*pub)->Publish(ping)) {
      ++timeouts;
      continue;
    }
    bool got = false;
    while ((*sub)->TakeFor(pong, std::chrono::seconds(2))) {
      if (Seq(pong) == seq) {
        got = true;
        break;
      }
    }
    if (!got) {
      ++timeouts;
      continue;
    }
    rtt_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
  }

  // Throughput: kWindow pings in flight.
  const std::uint64_t first = seq + 1;
  const std::uint64_t last = seq + static_cast<std::uint64_t>(throughput_n);
  std::uint64_t next = first;
  std::uint64_t done = 0;
  const auto t0 = Clock::now();
  for (int w = 0; w < kWindow && next <= last; ++w) {
    Seq(ping) = next++;
    (void)(*pub)->Publish(ping);
  }
  while (done < static_cast<std::uint64_t>(throughput_n)) {
    if (!(*sub)->TakeFor(pong, std::chrono::seconds(2))) {
      ++timeouts;
      break;
    }
    if (Seq(pong) < first) continue;
    ++done;
    if (next <= last) {
      Seq(ping) = next++;
      (void)(*pub)->Publish(ping);
    }
  }
  const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
  const double rts = secs > 0 ? static_cast<double>(done) / secs : 0.0;

  std::printf(
      "suite=bus scenario=rtt_%s backend=%s%s%s mode=%s interface=%s payload_bytes=%zu n=%zu "
      "p50_us=%.1f p99_us=%.1f max_us=%.1f timeouts=%d window=%d round_trips_s=%.0f msgs_s=%.0f "
      "mb_s=%.2f\n",
      size.c_str(), backend.c_str(), sc.echo_backend == backend ? "" : " echo_backend=",
      sc.echo_backend == backend ? "" : sc.echo_backend.c_str(), mode.c_str(),
      sc.interface.c_str(), payload_bytes, rtt_us.size(),
      Percentile(rtt_us, 0.50), Percentile(rtt_us, 0.99), Percentile(rtt_us, 1.0), timeouts,
      kWindow, rts, 2 * rts, 2 * rts * static_cast<double>(payload_bytes) / 1e6);
  std::fflush(stdout);
  return timeouts == 0 ? 0 : 1;
}

// Lockstep of a fleet across two processes: this process plays the physics server (publishes
// every drone's SensorSample for step k, then waits for every drone's ActuatorCommand of step k),
// the child plays `drones` agents. The server side reads answers as physics_server's BusTransport
// does: one reader on the keyed sim/actuator for every drone, answers matched to their drone by
// name in O(1) on the middleware's thread, and the main thread woken once the step's last answer
// is in (not once per answer). Figures: per-step latency (first publish to last command) and steps
// per second; at 250 Hz real time needs steps_s >= 250.
class FleetAnswers {
 public:
  explicit FleetAnswers(const std::vector<std::string>& names) : answered_(names.size(), false) {
    for (std::size_t i = 0; i < names.size(); ++i) index_of_.emplace(names[i], i);
  }
  // The middleware's thread.
  void On(const ActuatorCommand& c) {
    const auto it = index_of_.find(c.drone);
    if (it == index_of_.end()) return;
    std::lock_guard lock(mu_);
    if (c.step != step_ || answered_[it->second]) return;  // stale or duplicate
    answered_[it->second] = true;
    if (++count_ == answered_.size()) cv_.notify_one();
  }
  void Begin(std::uint64_t step) {
    std::lock_guard lock(mu_);
    step_ = step;
    count_ = 0;
    std::fill(answered_.begin(), answered_.end(), false);
  }
  // True once every drone answered the step; false at the timeout.
  bool WaitAll(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mu_);
    return cv_.wait_for(lock, timeout, [this] { return count_ == answered_.size(); });
  }
  std::vector<std::size_t> Missing() {
    std::lock_guard lock(mu_);
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < answered_.size(); ++i) {
      if (!answered_[i]) out.push_back(i);
    }
    return out;
  }

 private:
  std::unordered_map<std::string, std::size_t> index_of_;  // read-only after construction
  std::mutex mu_;
  std::condition_variable cv_;
  std::uint64_t step_ = 0;
  std::size_t count_ = 0;
  std::vector<bool> answered_;
};

int RunFleet(const Scenario& sc, int drones, int steps) {
  testing::EchoOptions o{.backend = sc.echo_backend, .domain_id = sc.domain,
                         .interface = sc.interface, .kind = "fleet", .drones = drones};
  auto echo = Echo::Start("two_process", o);
  if (!echo) return 1;
  auto p = Participant::Create({.backend = sc.backend, .domain_id = sc.domain, .interface = sc.interface});
  if (!p) {
    std::fprintf(stderr, "bus bench: %s\n", p.error().ToString().c_str());
    return 1;
  }
  std::vector<std::string> names;
  std::vector<std::unique_ptr<Publisher<SensorSample>>> pubs;
  for (int i = 0; i < drones; ++i) {
    names.push_back("drone_" + std::to_string(i));
    auto pub = (*p)->CreatePublisher<SensorSample>(SensorTopic(names.back()), Qos::kLockstep);
    if (!pub) {
      std::fprintf(stderr, "bus bench: fleet: cannot create endpoints\n");
      return 1;
    }
    pubs.push_back(std::move(*pub));
  }
  FleetAnswers answers(names);  // before `sub`: the subscriber goes first, no callback outlives it
  auto sub = (*p)->CreateSubscriber<ActuatorCommand>(kActuatorTopic, Qos::kLockstep,
                                                     [&answers](const ActuatorCommand& c) { answers.On(c); });
  if (!sub) {
    std::fprintf(stderr, "bus bench: fleet: %s\n", sub.error().ToString().c_str());
    return 1;
  }
  const auto match_deadline = Clock::now() + std::chrono::seconds(30);
  for (int i = 0; i < drones; ++i) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(match_deadline - Clock::now());
    if (!pubs[static_cast<std::size_t>(i)]->WaitForSubscribers(1, left)) {
      std::fprintf(stderr, "bus bench: fleet: drone %d did not match within 30 s\n", i);
      return 1;
    }
  }
  {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(match_deadline - Clock::now());
    if (!(*sub)->WaitForPublishers(drones, left)) {
      std::fprintf(stderr, "bus bench: fleet: the %d actuator writers did not match within 30 s\n", drones);
      return 1;
    }
  }
  SensorSample s = testing::FullSensorSample(1);
  // Handshake: resend step 0 to the drones that have not answered yet, every 100 ms.
  s.step = 0;
  answers.Begin(0);
  bool joined = false;
  for (const auto deadline = Clock::now() + std::chrono::seconds(30); !joined && Clock::now() < deadline;) {
    for (std::size_t i : answers.Missing()) {
      s.drone = names[i];
      (void)pubs[i]->Publish(s);
    }
    joined = answers.WaitAll(std::chrono::milliseconds(100));
  }
  if (!joined) {
    std::fprintf(stderr, "bus bench: fleet: %zu drones never answered step 0\n", answers.Missing().size());
    return 1;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // duplicate answers to the handshake
  std::vector<double> step_us;
  step_us.reserve(static_cast<std::size_t>(steps));
  int timeouts = 0;
  const ProcessUsage server0 = Usage(0), echo0 = Usage(echo->pid());
  const auto t_all = Clock::now();
  for (int k = 1; k <= steps && timeouts == 0; ++k) {
    const auto step = static_cast<std::uint64_t>(k);
    const auto t0 = Clock::now();
    answers.Begin(step);
    s.step = step;
    s.sim_time_ns = k * 4'000'000LL;
    for (std::size_t i = 0; i < pubs.size(); ++i) {
      s.drone = names[i];
      (void)pubs[i]->Publish(s);
    }
    if (!answers.WaitAll(std::chrono::seconds(2))) {
      ++timeouts;
      break;
    }
    step_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
  }
  const double secs = std::chrono::duration<double>(Clock::now() - t_all).count();
  const double steps_s = secs > 0 ? static_cast<double>(step_us.size()) / secs : 0.0;
  const ProcessUsage server1 = Usage(0), echo1 = Usage(echo->pid());
  const double n = std::max<double>(1.0, static_cast<double>(step_us.size()));
  const double server_us = static_cast<double>(server1.cpu_ns - server0.cpu_ns) / 1e3 / n;
  const double echo_us = static_cast<double>(echo1.cpu_ns - echo0.cpu_ns) / 1e3 / n;
  std::printf(
      "suite=bus scenario=lockstep_fleet backend=%s%s%s mode=two_process interface=%s drones=%d "
      "steps=%zu step_p50_us=%.1f step_p99_us=%.1f steps_s=%.0f msgs_s=%.0f "
      "max_hz_per_drone=%.0f cpu_us_per_step=%.0f server_cpu_us=%.0f agents_cpu_us=%.0f "
      "switches_per_step=%.1f steps_s_2cores=%.0f timeouts=%d\n",
      sc.backend.c_str(), sc.echo_backend == sc.backend ? "" : " echo_backend=",
      sc.echo_backend == sc.backend ? "" : sc.echo_backend.c_str(), sc.interface.c_str(), drones,
      step_us.size(), Percentile(step_us, 0.50), Percentile(step_us, 0.99), steps_s,
      2.0 * drones * steps_s, steps_s, server_us + echo_us, server_us, echo_us,
      static_cast<double>(server1.switches - server0.switches + echo1.switches - echo0.switches) / n,
      server_us + echo_us > 0 ? 2e6 / (server_us + echo_us) : 0.0, timeouts);
  std::fflush(stdout);
  return timeouts == 0 ? 0 : 1;
}

// One agent's sim-bus cost per step at real time: this process publishes drone_0's SensorSample
// every 4 ms (250 Hz, paced) and waits for its answer; the child answers as `kind` says:
//   waitset   (echo kind lockstep) the agent's own loop: TakeFor on its main thread (Cyclone's
//             receive thread takes the datagram and wakes the main thread), Publish from there;
//   callback  (echo kind fleet, 1 drone) the answer written from the reader's callback on the
//             receive thread: no hand-off to another thread.
// Figures: the child's CPU per step (every thread) and its context switches per step.
int RunAgentStep(const Scenario& sc, const std::string& kind, int steps) {
  testing::EchoOptions o{.backend = sc.echo_backend, .domain_id = sc.domain, .interface = sc.interface,
                         .kind = kind == "waitset" ? "lockstep" : "fleet", .drone = "drone_0", .drones = 1};
  auto echo = Echo::Start("two_process", o);
  if (!echo) return 1;
  auto p = Participant::Create({.backend = sc.backend, .domain_id = sc.domain, .interface = sc.interface});
  if (!p) {
    std::fprintf(stderr, "bus bench: %s\n", p.error().ToString().c_str());
    return 1;
  }
  const std::vector<std::string> names = {"drone_0"};
  auto pub = (*p)->CreatePublisher<SensorSample>(SensorTopic(names[0]), Qos::kLockstep);
  FleetAnswers answers(names);
  auto sub = (*p)->CreateSubscriber<ActuatorCommand>(kActuatorTopic, Qos::kLockstep,
                                                     [&answers](const ActuatorCommand& c) { answers.On(c); });
  if (!pub || !sub || !(*pub)->WaitForSubscribers(1, std::chrono::seconds(15)) ||
      !(*sub)->WaitForPublishers(1, std::chrono::seconds(15))) {
    std::fprintf(stderr, "bus bench: agent_step: no match\n");
    return 1;
  }
  SensorSample s = testing::FullSensorSample(1);
  s.drone = names[0];
  s.step = 0;
  answers.Begin(0);
  bool joined = false;
  for (int i = 0; i < 100 && !joined; ++i) {
    (void)(*pub)->Publish(s);
    joined = answers.WaitAll(std::chrono::milliseconds(100));
  }
  if (!joined) {
    std::fprintf(stderr, "bus bench: agent_step: the agent never answered\n");
    return 1;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  int timeouts = 0;
  constexpr auto kPeriod = std::chrono::microseconds(4000);
  const ProcessUsage agent0 = Usage(echo->pid());
  const auto t_start = Clock::now();
  int done = 0;
  for (int k = 1; k <= steps && timeouts == 0; ++k, ++done) {
    std::this_thread::sleep_until(t_start + k * kPeriod);
    answers.Begin(static_cast<std::uint64_t>(k));
    s.step = static_cast<std::uint64_t>(k);
    (void)(*pub)->Publish(s);
    if (!answers.WaitAll(std::chrono::seconds(2))) ++timeouts;
  }
  const ProcessUsage agent1 = Usage(echo->pid());
  const double n = std::max(1, done);
  std::printf(
      "suite=bus scenario=agent_step backend=%s answer=%s interface=%s steps=%d rate_hz=250 "
      "agent_cpu_us_per_step=%.1f agent_switches_per_step=%.2f agent_core_fraction=%.4f timeouts=%d\n",
      sc.echo_backend.c_str(), kind.c_str(), sc.interface.c_str(), done,
      static_cast<double>(agent1.cpu_ns - agent0.cpu_ns) / 1e3 / n,
      static_cast<double>(agent1.switches - agent0.switches) / n,
      static_cast<double>(agent1.cpu_ns - agent0.cpu_ns) / 1e3 / n / 4000.0, timeouts);
  std::fflush(stdout);
  return timeouts == 0 ? 0 : 1;
}

// The kernel's floor under the lockstep fleet: the same 2N datagrams a step (N of 300 B out, N
// back, one at a time), between this process and a forked child over UDP on loopback, no DDS.
// Whatever middleware carries a per-drone sample and a per-drone answer sits above this.
int RunUdpFloor(int drones, int steps) {
  constexpr int kBytes = 300;  // about a SensorSample / ActuatorCommand on the wire
  auto make = [](std::uint16_t port) {
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    int size = 4 << 20;
    (void)::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &size, sizeof size);
    if (fd < 0 || ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) return -1;
    return fd;
  };
  constexpr std::uint16_t kServerPort = 47311, kEchoPort = 47312;
  auto to = [](std::uint16_t port) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return a;
  };
  const int server = make(kServerPort);
  const int echo_fd = make(kEchoPort);
  if (server < 0 || echo_fd < 0) {
    std::fprintf(stderr, "bus bench: udp_floor: cannot bind UDP ports %d/%d on loopback\n", kServerPort, kEchoPort);
    return 1;
  }
  const long total = static_cast<long>(drones) * steps;
  const pid_t child = ::fork();
  if (child == 0) {  // the echo: answer every datagram
    char buf[2048];
    const sockaddr_in back = to(kServerPort);
    for (long i = 0; i < total; ++i) {
      if (::recv(echo_fd, buf, sizeof buf, 0) < 0) ::_exit(1);
      (void)::sendto(echo_fd, buf, kBytes, 0, reinterpret_cast<const sockaddr*>(&back), sizeof back);
    }
    ::_exit(0);
  }
  ::close(echo_fd);
  char buf[2048] = {};
  const sockaddr_in out = to(kEchoPort);
  const ProcessUsage server0 = Usage(0), echo0 = Usage(child);
  const auto t0 = Clock::now();
  for (int k = 0; k < steps; ++k) {
    for (int d = 0; d < drones; ++d) {
      (void)::sendto(server, buf, kBytes, 0, reinterpret_cast<const sockaddr*>(&out), sizeof out);
    }
    for (int d = 0; d < drones; ++d) (void)::recv(server, buf, sizeof buf, 0);
  }
  const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
  const ProcessUsage server1 = Usage(0), echo1 = Usage(child);
  int status = 0;
  (void)::waitpid(child, &status, 0);
  ::close(server);
  const double cpu_us = static_cast<double>(server1.cpu_ns - server0.cpu_ns + echo1.cpu_ns - echo0.cpu_ns) / 1e3 / steps;
  std::printf("suite=bus scenario=udp_floor drones=%d steps=%d steps_s=%.0f cpu_us_per_step=%.0f steps_s_2cores=%.0f\n",
              drones, steps, secs > 0 ? steps / secs : 0.0, cpu_us, cpu_us > 0 ? 2e6 / cpu_us : 0.0);
  std::fflush(stdout);
  return 0;
}

std::vector<std::string> Pick(const std::string& value, std::vector<std::string> all) {
  if (value == "all") return all;
  return {value};
}

int RunBusBench(const Args& args) {
  if (args.Get("role", "") == "echo") return RunEchoRole(args);
  const auto backends = Pick(args.Get("backend", "all"), {"cyclonedds", "fastdds"});
  const auto modes = Pick(args.Get("mode", "all"), {"same_process", "two_process"});
  const auto sizes = Pick(args.Get("size", "all"), {"small", "large"});
  int domain = static_cast<int>(args.GetInt("domain", 200));
  const std::string interface = args.Get("interface", "lo");
  const std::string echo_backend = args.Get("echo-backend", "");
  std::string scenario = args.Get("scenario", "all");
  // lockstep_fleet: the name the fleet lines carry (scenario=lockstep_fleet), accepted as well.
  if (scenario == "lockstep_fleet") scenario = "fleet";
  if (scenario != "all" && scenario != "rtt" && scenario != "fleet" && scenario != "agent_step" &&
      scenario != "udp_floor") {
    std::fprintf(stderr,
                 "bus bench: unknown --scenario '%s': accepted rtt, fleet (lockstep_fleet), agent_step, "
                 "udp_floor, all\n",
                 scenario.c_str());
    return 2;
  }
  if (scenario == "udp_floor") {  // not part of "all"
    return RunUdpFloor(static_cast<int>(args.GetInt("drones", 100)),
                       static_cast<int>(args.GetInt("steps", args.quick ? 200 : 3000)));
  }
  if (scenario == "agent_step") {  // not part of "all": it runs paced, in real time
    int worst = 0;
    for (const auto& backend : backends) {
      for (const std::string kind : {"waitset", "callback"}) {
        const Scenario sc{backend, echo_backend.empty() ? backend : echo_backend, "two_process", "agent",
                          interface, domain++};
        const int steps = static_cast<int>(args.GetInt("steps", args.quick ? 250 : 2500));
        if (const int rc = RunAgentStep(sc, kind, steps); rc != 0) worst = rc;
      }
    }
    return worst;
  }
  int worst = 0;
  for (const auto& backend : backends) {
    if (scenario == "rtt") break;
    std::vector<int> fleet_sizes = args.quick ? std::vector<int>{10} : std::vector<int>{10, 50, 100};
    if (args.options.count("drones") != 0) fleet_sizes = {static_cast<int>(args.GetInt("drones", 10))};
    for (int drones : fleet_sizes) {
      const Scenario sc{backend, echo_backend.empty() ? backend : echo_backend, "two_process",
                        "fleet", interface, domain++};
      const int steps = static_cast<int>(args.GetInt("steps", args.quick ? 100 : 1000));
      if (const int rc = RunFleet(sc, drones, steps); rc != 0) worst = rc;
    }
  }
  for (const auto& backend : backends) {
    if (scenario == "fleet") break;
    for (const auto& mode : modes) {
      for (const auto& size : sizes) {
        int rc = 0;
        const Scenario sc{backend, echo_backend.empty() ? backend : echo_backend, mode, size,
                          interface, domain};
        if (size == "small") {
          const int n = static_cast<int>(args.GetInt("n", args.quick ? 200 : 5000));
          rc = RunScenario<RaftMessage>(sc, testing::FullRaftMessage(1, kSmallPayloadBytes),
                                        kSmallPayloadBytes, n, args.quick ? 500 : 20000);
        } else if (size == "large") {
          const int n = static_cast<int>(args.GetInt("n", args.quick ? 30 : 500));
          CameraImage img = testing::FullCameraImage(1, 320, 240);
          const std::size_t bytes = img.data.size();
          rc = RunScenario<CameraImage>(sc, std::move(img), bytes, n,
                                        args.quick ? 60 : 1000);
        } else {
          std::fprintf(stderr, "bus bench: unknown --size '%s': accepted small, large, all\n",
                       size.c_str());
          return 2;
        }
        if (rc != 0) worst = rc;
        ++domain;
      }
    }
  }
  return worst;
}

}  // namespace
}  // namespace swarmbox::bus

SWARMBOX_BENCH_SUITE(bus, "DDS round-trip latency and throughput per backend (--quick)",
                     swarmbox::bus::RunBusBench);
