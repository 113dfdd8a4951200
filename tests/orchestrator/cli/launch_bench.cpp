// swarmbox-bench launch: how fast a trial comes up and goes down, `swarmbox run` against the
// docker-compose file `swarmbox compose` exports for the same trial, in the same run.
//
//   swarmbox-bench launch [--quick] [--drones=3,10,20] [--keep=1]
//
// Per fleet size N (default 3, 10 and 20 drones; --quick: 3): the fleet of trials/demo_flight.yaml
// replaced by N x500 scouts on a 4 m grid, ending on the physics server's first progress line
// (`event=clock`, 10 s simulated), paced at rtf 1.
//   1. `swarmbox run` (images built beforehand, untimed): from starting the program to the last
//      agent's `event=ready` line (run_ready_s), and from the ending line to the last container
//      stopped (end_to_stopped_s) and to swarmbox's exit (end_to_exit_s).
//   2. `swarmbox compose` (untimed), then `docker-compose up -d`: from starting docker-compose to
//      the last agent's `event=ready` (compose_ready_s), and the time `up -d` itself took; then
//      `docker-compose down` (compose_down_s, for reference).
//   3. The floor for a launcher that keeps the trial's order (the physics server ready before
//      any agent starts): engine_start_floor_s, N containers of a trivial program
//      (swarmbox-e2e-node, idle until stopped) created beforehand on two fresh networks with
//      fixed addresses, as the trial's agents are (untimed), then started all at once, one
//      request each, from the first start request to the last `start` event; plus
//      physics_start_to_ready_s, the physics server's own start (its container's `start` event
//      to its event=ready line) in the run of step 1. in_order_floor_s is their sum, and
//      floor_over_compose = in_order_floor_s / compose_ready_s. The same containers are then
//      stopped all at once: the first stop request to the last `die` event (engine_stop_floor_s,
//      the engine's part of one level's stop, to set end_to_stopped_s against).
// Every time comes from the engine (log line timestamps and `start`/`die` events, both on this
// host's real time clock), watched by the bench itself, so every path is measured the same way.
// The exported file's fixed subnets move to a free pair when another network on the engine holds
// them.
// Aims (issue 6): ratio = run_ready_s / compose_ready_s <= 0.5; end_to_stopped_s < 1. The ratio
// aim is out of reach for a launcher that keeps the trial's order when floor_over_compose > 0.5
// (floor_rules_out_ratio_aim=yes); "no" only means that the floor does not rule it out (the
// agents' own start-up, the networks and the creations come on top).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "bench.hpp"
#include "launch_timing.hpp"
#include "orchestrator/runner/e2e_node_image.hpp"
#include "support/child_process.hpp"
#include "support/files.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/images/find_program.hpp"
#include "swarmbox/runner/naming.hpp"
#include "swarmbox/runner/subnets.hpp"

namespace swarmbox {
namespace {

namespace fs = std::filesystem;
using cli::testing::LaunchTimes;
using swarmbox::testing::ChildProcess;
using swarmbox::testing::ReadWholeFile;
using swarmbox::testing::RunToEnd;

constexpr char kSwarmbox[] = SWARMBOX_LAUNCH_SWARMBOX_EXE;
constexpr char kTrial[] = SWARMBOX_LAUNCH_TRIAL;
constexpr char kComposeRunId[] = "compose";  // what `swarmbox compose` labels its export with
constexpr char kEndPattern[] = "event=clock";
constexpr char kEndComponent[] = "physics";

std::int64_t NowUnixNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Watches the engine for one run id: container start/die events, and each started container's
// log (followed with Docker's timestamps) for its first `event=ready` and the ending line.
class EngineWatch {
 public:
  // follow_logs: follow each started container's log (ready and ending lines).
  EngineWatch(docker::DockerApi& api, std::string run_id, bool follow_logs = true)
      : api_(api), run_id_(std::move(run_id)), follow_logs_(follow_logs) {
    docker::EventFilter filter;
    filter.labels.equals[std::string(docker::kLabelRun)] = run_id_;
    filter.types = {"container"};
    filter.actions = {"start", "die"};
    // Replays from a second ago: nothing is lost while the stream connects.
    filter.since_unix_s = NowUnixNs() / 1'000'000'000 - 1;
    since_ns_ = (filter.since_unix_s) * 1'000'000'000;
    events_ = std::thread([this, filter] {
      Status s = api_.StreamEvents(filter, [this](const docker::Event& e) { OnEvent(e); }, &cancel_);
      if (!s && s.error().code() != ErrorCode::kCancelled) {
        std::lock_guard<std::mutex> lock(mu_);
        errors_.push_back("events: " + s.error().ToString());
      }
    });
  }
  ~EngineWatch() {
    cancel_.Cancel();
    events_.join();
    std::vector<std::thread> followers;
    {
      std::lock_guard<std::mutex> lock(mu_);
      followers.swap(followers_);
    }
    for (std::thread& t : followers) t.join();
  }
  EngineWatch(const EngineWatch&) = delete;
  EngineWatch& operator=(const EngineWatch&) = delete;

  // Until every one of `agents` logged event=ready, or the deadline.
  bool WaitReady(const std::vector<std::string>& agents, std::chrono::steady_clock::time_point deadline) {
    std::unique_lock<std::mutex> lock(mu_);
    return cv_.wait_until(lock, deadline, [&] {
      return std::all_of(agents.begin(), agents.end(),
                         [&](const std::string& a) { return times_.ready_ns.count(a) > 0; });
    });
  }
  // Until every container that started has died, or the deadline.
  bool WaitAllDied(std::chrono::steady_clock::time_point deadline) {
    std::unique_lock<std::mutex> lock(mu_);
    return cv_.wait_until(lock, deadline, [&] { return !started_.empty() && died_.size() >= started_.size(); });
  }
  LaunchTimes Times() {
    std::lock_guard<std::mutex> lock(mu_);
    LaunchTimes t = times_;
    t.died_ns.clear();
    for (const auto& [id, ns] : died_) t.died_ns.push_back(ns);
    return t;
  }
  std::vector<std::string> Errors() {
    std::lock_guard<std::mutex> lock(mu_);
    return errors_;
  }
  std::size_t started() {
    std::lock_guard<std::mutex> lock(mu_);
    return started_.size();
  }
  // Until `n` containers have started, or the deadline; then the last start's engine time.
  std::optional<std::int64_t> WaitStarted(std::size_t n, std::chrono::steady_clock::time_point deadline) {
    std::unique_lock<std::mutex> lock(mu_);
    if (!cv_.wait_until(lock, deadline, [&] { return started_.size() >= n; })) return std::nullopt;
    return last_start_ns_;
  }

 private:
  void OnEvent(const docker::Event& e) {
    std::lock_guard<std::mutex> lock(mu_);
    if (e.time_unix_ns < since_ns_) return;
    if (e.action == "die") {
      died_[e.actor_id] = e.time_unix_ns;
      cv_.notify_all();
      return;
    }
    if (e.action != "start" || !started_.insert(e.actor_id).second) return;
    last_start_ns_ = std::max(last_start_ns_, e.time_unix_ns);
    cv_.notify_all();
    if (!follow_logs_) return;
    auto c = e.attributes.find(std::string(docker::kLabelComponent));
    const std::string component = c == e.attributes.end() ? e.actor_id : c->second;
    times_.start_ns.emplace(component, e.time_unix_ns);
    followers_.emplace_back([this, id = e.actor_id, component] { Follow(id, component); });
  }

  void Follow(const std::string& id, const std::string& component) {
    docker::LogOptions o;
    o.follow = true;
    o.timestamps = true;
    Status s = api_.FollowLogs(id, o, [&](const docker::LogLine& line) {
      auto stamped = cli::testing::SplitStampedLine(line.text);
      if (!stamped) return;
      std::lock_guard<std::mutex> lock(mu_);
      if (stamped->text.find("event=ready") != std::string_view::npos &&
          times_.ready_ns.count(component) == 0) {
        times_.ready_ns[component] = stamped->time_ns;
        cv_.notify_all();
      }
      if (component == kEndComponent && !times_.end_line_ns &&
          stamped->text.find(kEndPattern) != std::string_view::npos) {
        times_.end_line_ns = stamped->time_ns;
      }
    }, &cancel_);
    // A container removed right after it stopped can end the stream with "no such container".
    if (!s && s.error().code() != ErrorCode::kCancelled && s.error().code() != ErrorCode::kNotFound) {
      std::lock_guard<std::mutex> lock(mu_);
      errors_.push_back("logs of " + component + ": " + s.error().ToString());
    }
  }

  docker::DockerApi& api_;
  std::string run_id_;
  bool follow_logs_ = true;
  std::int64_t since_ns_ = 0;
  std::int64_t last_start_ns_ = 0;
  docker::CancelToken cancel_;
  std::mutex mu_;
  std::condition_variable cv_;
  LaunchTimes times_;
  std::set<std::string> started_;
  std::map<std::string, std::int64_t> died_;
  std::vector<std::thread> followers_;
  std::vector<std::string> errors_;
  std::thread events_;
};

std::string TrialName(int drones) { return "launch" + std::to_string(drones) + "-" + std::to_string(::getpid()); }

// --set arguments: N x500 scouts on a 4 m grid, the end on the physics server's first clock line.
std::vector<std::string> TrialSets(int drones) {
  std::string list = "[";
  for (int i = 0; i < drones; ++i) {
    if (i > 0) list += ", ";
    list += "{name: scout_" + std::to_string(i + 1) + ", airframe: x500, pose: [" +
            std::to_string((i % 5) * 4) + ", " + std::to_string((i / 5) * 4) + ", 0]}";
  }
  list += "]";
  // The name is per bench process: a network Docker failed to release in an earlier run ("has
  // active endpoints" until the engine restarts) cannot be picked up by name.
  return {"--set", "name=" + TrialName(drones),
          "--set", "drones=" + list,
          "--set", std::string("end=[{on: \"") + kEndPattern + "\", from: " + kEndComponent +
                       ", outcome: success}]",
          "--set", "physics.rtf=1",
          "--set", "timeout.sim=60s",
          "--set", "timeout.wall=10m"};
}

std::vector<std::string> AgentNames(int drones) {
  std::vector<std::string> names;
  for (int i = 0; i < drones; ++i) names.push_back("scout_" + std::to_string(i + 1));
  return names;
}

std::string Fmt(std::optional<double> v) {
  if (!v) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", *v);
  return buf;
}

double SecondsSince(std::int64_t from_ns) { return static_cast<double>(NowUnixNs() - from_ns) / 1e9; }

// Removes everything labelled with the run; networks whose endpoints Docker is still releasing
// ("has active endpoints") are retried for a few seconds. `left`: what is still there afterwards.
void RemoveRun(docker::DockerApi& api, const std::string& run_id, const std::string& trial,
               std::size_t* left) {
  docker::LabelSelector run;
  run.equals[std::string(docker::kLabelRun)] = run_id;
  run.equals[std::string(docker::kLabelTrial)] = trial;
  for (int attempt = 0; attempt < 20; ++attempt) {
    auto removed = docker::RemoveLabelled(api, run, /*include_images=*/false);
    if (removed && removed->failures.empty()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  auto containers = api.ListContainers(run, /*all=*/true);
  auto networks = api.ListNetworks(run);
  *left = (containers ? containers->size() : 0) + (networks ? networks->size() : 0);
}

// The exported file's subnets are fixed (run id "compose"); when another network on this engine
// holds one of them, both /24s move to a pair that is free (addresses keep their host part).
// Timing does not depend on the addresses.
Status MoveComposeSubnetsIfTaken(docker::DockerApi& api, const fs::path& file) {
  std::string text = ReadWholeFile(file.string());
  auto nets = api.ListNetworks({});
  if (!nets) return nets.error();
  std::vector<std::string> taken;
  for (const auto& n : *nets) {
    if (!n.subnet.empty()) taken.push_back(n.subnet);
  }
  auto exported = runner::PickSubnets(kComposeRunId, 0, {});
  if (!exported) return exported.error();
  const std::string sim = exported->sim.ToString(), mesh = exported->mesh.ToString();
  if (std::find(taken.begin(), taken.end(), sim) == taken.end() &&
      std::find(taken.begin(), taken.end(), mesh) == taken.end()) {
    return Ok{};
  }
  auto free = runner::PickSubnets("launch-bench-" + std::to_string(::getpid()), 0, taken);
  if (!free) return free.error();
  auto prefix = [](const std::string& cidr) {  // "10.201.230.0/24" -> "10.201.230."
    return cidr.substr(0, cidr.rfind('.') + 1);
  };
  auto replace_all = [&](const std::string& from, const std::string& to) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
      text.replace(at, from.size(), to);
    }
  };
  replace_all("\"" + prefix(sim), "\"" + prefix(free->sim.ToString()));
  replace_all("\"" + prefix(mesh), "\"" + prefix(free->mesh.ToString()));
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << text;
  if (!out) return Error(ErrorCode::kIo, "cannot rewrite", file.string());
  std::fprintf(stderr, "launch: exported subnets %s and %s are taken on this engine; using %s and %s\n",
               sim.c_str(), mesh.c_str(), free->sim.ToString().c_str(), free->mesh.ToString().c_str());
  return Ok{};
}

// Step 3 (see the top): N idle containers on two fresh networks, started all at once, then
// stopped all at once.
struct EngineFloor {
  double start_s = 0;            // the first start request to the last `start` event
  std::optional<double> stop_s;  // the first stop request to the last `die` event
};
// `left`: what is still there after the clean-up (a stale network), as for the runs.
Result<EngineFloor> MeasureEngineFloor(docker::DockerApi& api, int drones, const std::string& image,
                                       std::size_t* left) {
  const std::string run_id = "floor-" + std::to_string(::getpid());
  const std::string trial = TrialName(drones);
  const docker::Labels labels = {{std::string(docker::kLabelRun), run_id},
                                 {std::string(docker::kLabelTrial), trial}};
  auto clean = [&] { RemoveRun(api, run_id, trial, left); };
  auto nets = api.ListNetworks({});
  if (!nets) return nets.error();
  std::vector<std::string> taken;
  for (const auto& n : *nets) {
    if (!n.subnet.empty()) taken.push_back(n.subnet);
  }
  auto subnets = runner::PickSubnets(run_id + "/" + trial, 0, taken);
  if (!subnets) return subnets.error();
  std::vector<std::string> network_ids;
  const std::vector<std::pair<std::string, runner::Ipv4Net>> wanted = {{"sim", subnets->sim},
                                                                         {"mesh", subnets->mesh}};
  for (const auto& [suffix, cidr] : wanted) {
    docker::NetworkSpec spec;
    spec.name = trial + "-floor-" + suffix;
    spec.subnet = cidr.ToString();
    spec.labels = labels;
    auto id = api.CreateNetwork(spec);
    if (!id) {
      clean();
      return id.error();
    }
    network_ids.push_back(*id);
  }
  std::vector<std::string> ids;
  for (int i = 0; i < drones; ++i) {
    docker::ContainerSpec spec;
    spec.name = trial + "-floor-" + std::to_string(i + 1);
    spec.image = image;
    spec.cmd = {"--name", "floor_" + std::to_string(i + 1), "--quiet-ticks"};
    spec.labels = labels;
    // Fixed addresses, as the trial's containers have.
    const auto host = static_cast<std::uint32_t>(10 + i);
    spec.networks = {{.network = network_ids[0], .ipv4_address = subnets->sim.Host(host), .aliases = {}},
                     {.network = network_ids[1], .ipv4_address = subnets->mesh.Host(host), .aliases = {}}};
    auto id = api.CreateContainer(spec);
    if (!id) {
      clean();
      return id.error();
    }
    ids.push_back(*id);
  }
  Result<EngineFloor> floor = Error(ErrorCode::kTimeout, "not every container started within 2 minutes");
  {
    EngineWatch watch(api, run_id, /*follow_logs=*/false);
    std::vector<Status> started(ids.size(), Ok{});
    const std::int64_t first_ns = NowUnixNs();
    std::vector<std::thread> starters;
    for (std::size_t i = 0; i < ids.size(); ++i) {
      starters.emplace_back([&, i] { started[i] = api.StartContainer(ids[i]); });
    }
    for (std::thread& t : starters) t.join();
    Status failed = Ok{};
    for (const Status& st : started) {
      if (!st) failed = st;
    }
    if (!failed) {
      floor = failed.error();
    } else if (auto last = watch.WaitStarted(ids.size(), std::chrono::steady_clock::now() + std::chrono::minutes(2))) {
      EngineFloor f;
      f.start_s = static_cast<double>(*last - first_ns) / 1e9;
      // Then stopped all at once, as a trial's level is: the first stop request to the last `die`.
      const std::int64_t stop_ns = NowUnixNs();
      std::vector<std::thread> stoppers;
      for (const std::string& id : ids) stoppers.emplace_back([&api, &id] { (void)api.StopContainer(id, 10); });
      for (std::thread& t : stoppers) t.join();
      if (watch.WaitAllDied(std::chrono::steady_clock::now() + std::chrono::minutes(1))) {
        const LaunchTimes t = watch.Times();
        f.stop_s = static_cast<double>(*std::max_element(t.died_ns.begin(), t.died_ns.end()) - stop_ns) / 1e9;
      }
      floor = f;
    }
  }
  clean();
  return floor;
}

struct ScenarioResult {
  bool ok = true;
  std::string line;
};

ScenarioResult RunScenario(docker::DockerApi& api, int drones, const fs::path& scratch,
                           const std::string& compose_exe, const std::string& floor_image) {
  using std::chrono::minutes;
  using std::chrono::steady_clock;
  const std::vector<std::string> agents = AgentNames(drones);
  const std::vector<std::string> sets = TrialSets(drones);
  const std::string trial = TrialName(drones);
  std::ostringstream line;
  line << "suite=launch scenario=drones_" << drones << " drones=" << drones;
  auto fail = [&](const std::string& why) {
    line << " error=\"" << why << "\"";
    return ScenarioResult{false, line.str()};
  };

  // 1. swarmbox run.
  const std::string run_id = runner::NewRunId();
  std::vector<std::string> argv = {kSwarmbox, "run", kTrial, "--quiet", "--out", scratch.string(),
                                   "--run-id", run_id};
  argv.insert(argv.end(), sets.begin(), sets.end());
  std::optional<double> run_ready_s, end_to_stopped_s, end_to_exit_s, physics_start_to_ready_s;
  std::size_t run_left = 0;
  {
    EngineWatch watch(api, run_id);
    const std::int64_t spawn_ns = NowUnixNs();
    const std::string err = (scratch / ("run-" + std::to_string(drones) + ".err")).string();
    auto child = ChildProcess::Spawn(argv, "", err);
    if (!child) return fail(child.error().ToString());
    const bool ready = watch.WaitReady(agents, steady_clock::now() + minutes(5));
    const std::optional<int> code = child->Wait(minutes(10));
    const std::int64_t exited_ns = NowUnixNs();
    (void)watch.WaitAllDied(steady_clock::now() + std::chrono::seconds(10));
    LaunchTimes times = watch.Times();
    times.spawn_ns = spawn_ns;
    if (code) times.exited_ns = exited_ns;
    const auto figures = cli::testing::ComputeLaunchFigures(times, agents);
    run_ready_s = figures.ready_s;
    end_to_stopped_s = figures.end_to_stopped_s;
    end_to_exit_s = figures.end_to_exit_s;
    physics_start_to_ready_s = cli::testing::StartToReady(times, kEndComponent);
    if (!code) {
      child->Signal(SIGINT);
      (void)child->Wait(minutes(1));
    }
    RemoveRun(api, run_id, trial, &run_left);
    for (const std::string& e : watch.Errors()) std::fprintf(stderr, "launch: %s\n", e.c_str());
    if (!ready || !code || *code != 0) {
      line << " run_exit=" << (code ? std::to_string(*code) : "hung") << " run_ready_s=" << Fmt(run_ready_s);
      if (!figures.not_ready.empty()) line << " not_ready=" << figures.not_ready.size();
      std::fprintf(stderr, "launch: swarmbox run (%d drones) said:\n%s\n", drones, ReadWholeFile(err).c_str());
      return fail("swarmbox run did not launch and end as expected");
    }
  }

  // 2. The exported compose file, brought up by docker-compose.
  const fs::path compose_file = scratch / ("launch" + std::to_string(drones) + ".compose.yaml");  // -o
  std::vector<std::string> export_argv = {kSwarmbox, "compose", kTrial, "-o", compose_file.string()};
  export_argv.insert(export_argv.end(), sets.begin(), sets.end());
  auto exported = RunToEnd(export_argv, minutes(2), scratch.string());
  if (!exported || exported->code != 0) {
    return fail("swarmbox compose: " + (exported ? exported->err : exported.error().ToString()));
  }
  if (Status moved = MoveComposeSubnetsIfTaken(api, compose_file); !moved) {
    return fail("compose subnets: " + moved.error().ToString());
  }
  const std::string project = "swarmbox-bench-launch";
  std::optional<double> compose_ready_s, compose_up_s, compose_down_s;
  std::size_t compose_left = 0;
  bool compose_ok = true;
  std::string compose_error;
  {
    EngineWatch watch(api, kComposeRunId);
    const std::int64_t spawn_ns = NowUnixNs();
    const std::string err = (scratch / ("compose-" + std::to_string(drones) + ".err")).string();
    auto up = ChildProcess::Spawn({compose_exe, "-f", compose_file.string(), "-p", project, "up", "-d"}, "", err);
    if (!up) return fail(up.error().ToString());
    // Until every agent is ready; `up -d` returns before that (its time is noted), or fails.
    const auto deadline = steady_clock::now() + minutes(5);
    std::optional<int> code;
    bool ready = false;
    while (!ready && steady_clock::now() < deadline) {
      if (!code && (code = up->Wait(std::chrono::milliseconds(0)))) {
        compose_up_s = SecondsSince(spawn_ns);
        if (*code != 0) break;
      }
      ready = watch.WaitReady(agents, steady_clock::now() + std::chrono::milliseconds(5));
    }
    if (!code && (code = up->Wait(minutes(2)))) compose_up_s = SecondsSince(spawn_ns);
    LaunchTimes times = watch.Times();
    times.spawn_ns = spawn_ns;
    compose_ready_s = cli::testing::ComputeLaunchFigures(times, agents).ready_s;
    if (!ready || !code || *code != 0) {
      compose_ok = false;
      compose_error = "docker-compose up did not bring every agent up: " + ReadWholeFile(err);
    }
    const std::int64_t down_ns = NowUnixNs();
    auto down = RunToEnd({compose_exe, "-f", compose_file.string(), "-p", project, "down", "-v"}, minutes(5),
                         scratch.string());
    if (down && down->code == 0) {
      compose_down_s = SecondsSince(down_ns);
    } else {
      std::fprintf(stderr, "launch: docker-compose down (%d drones) failed: %s\n", drones,
                   down ? down->err.c_str() : down.error().ToString().c_str());
    }
    RemoveRun(api, kComposeRunId, trial, &compose_left);
  }

  // 3. The engine's floor.
  std::optional<double> floor_s, stop_floor_s;
  std::size_t floor_left = 0;
  if (auto f = MeasureEngineFloor(api, drones, floor_image, &floor_left)) {
    floor_s = f->start_s;
    stop_floor_s = f->stop_s;
  } else {
    std::fprintf(stderr, "launch: the engine's floor (%d containers): %s\n", drones, f.error().ToString().c_str());
  }

  line << " run_ready_s=" << Fmt(run_ready_s) << " compose_ready_s=" << Fmt(compose_ready_s);
  std::optional<double> ratio, in_order_floor_s, floor_over_compose;
  if (run_ready_s && compose_ready_s && *compose_ready_s > 0) ratio = *run_ready_s / *compose_ready_s;
  if (floor_s && physics_start_to_ready_s) in_order_floor_s = *floor_s + *physics_start_to_ready_s;
  if (in_order_floor_s && compose_ready_s && *compose_ready_s > 0) {
    floor_over_compose = *in_order_floor_s / *compose_ready_s;
  }
  line << " ratio=" << Fmt(ratio) << " end_to_stopped_s=" << Fmt(end_to_stopped_s)
       << " end_to_exit_s=" << Fmt(end_to_exit_s) << " compose_up_returned_s=" << Fmt(compose_up_s)
       << " compose_down_s=" << Fmt(compose_down_s)
       << " physics_start_to_ready_s=" << Fmt(physics_start_to_ready_s) << " engine_start_floor_s=" << Fmt(floor_s)
       << " in_order_floor_s=" << Fmt(in_order_floor_s) << " floor_over_compose=" << Fmt(floor_over_compose)
       << " engine_stop_floor_s=" << Fmt(stop_floor_s)
       << " aim_ratio_met=" << (ratio && *ratio <= 0.5 ? "yes" : "no")
       << " floor_rules_out_ratio_aim=" << (!floor_over_compose ? "unknown" : *floor_over_compose > 0.5 ? "yes" : "no")
       << " aim_stop_met=" << (end_to_stopped_s && *end_to_stopped_s < 1.0 ? "yes" : "no")
       << " left=" << run_left + compose_left + floor_left;
  if (!compose_ok) {
    std::fprintf(stderr, "launch: %s\n", compose_error.c_str());
    return fail("docker-compose launch failed");
  }
  return ScenarioResult{true, line.str()};
}

int RunLaunchBench(const bench::Args& args) {
  std::vector<int> sizes = {3, 10, 20};
  if (args.quick) sizes = {3};
  if (auto list = args.Get("drones", ""); !list.empty()) {
    sizes.clear();
    std::stringstream s(list);
    std::string item;
    while (std::getline(s, item, ',')) sizes.push_back(std::atoi(item.c_str()));
  }
  for (int n : sizes) {
    if (n < 1 || n > 200) {
      std::printf("suite=launch error=\"--drones: %d is not a fleet size in 1..200\"\n", n);
      return 2;
    }
  }
  auto compose = images::FindProgram("docker-compose", "", {}, "scripts/setup.sh installs it");
  if (!compose) {
    std::printf("suite=launch error=\"%s\"\n", compose.error().ToString().c_str());
    return 1;
  }
  const std::string compose_exe = *compose;
  auto api = docker::DockerClient::Connect({.socket_path = docker::DefaultSocketPath(),
                                            .connect_timeout = std::chrono::seconds(5),
                                            .request_timeout = std::chrono::seconds(120)});
  if (!api) {
    std::printf("suite=launch error=\"%s\"\n", api.error().ToString().c_str());
    return 1;
  }
  const fs::path scratch = fs::temp_directory_path() / ("swarmbox-bench-launch-" + std::to_string(::getpid()));
  fs::create_directories(scratch);
  // The images first (untimed): both paths then start from images that exist.
  auto images = RunToEnd({kSwarmbox, "images", "--no-faults"}, std::chrono::minutes(10), scratch.string());
  if (!images || images->code != 0) {
    std::printf("suite=launch error=\"swarmbox images failed: %s\"\n",
                images ? images->err.c_str() : images.error().ToString().c_str());
    fs::remove_all(scratch);
    return 1;
  }
  auto floor_image = swarmbox::testing::EnsureE2eNodeImage(**api, SWARMBOX_LAUNCH_E2E_NODE);
  if (!floor_image) {
    std::printf("suite=launch error=\"the floor's image: %s\"\n", floor_image.error().ToString().c_str());
    fs::remove_all(scratch);
    return 1;
  }
  int failures = 0;
  for (int n : sizes) {
    ScenarioResult r = RunScenario(**api, n, scratch, compose_exe, *floor_image);
    std::printf("%s\n", r.line.c_str());
    std::fflush(stdout);
    if (!r.ok) ++failures;
  }
  if (args.Get("keep", "0") == "0") fs::remove_all(scratch);  // else: the logs and compose files
  return failures == 0 ? 0 : 1;
}

}  // namespace
}  // namespace swarmbox

SWARMBOX_BENCH_SUITE(launch, "swarmbox run vs the exported docker-compose file: launch to ready, end to stopped",
                     swarmbox::RunLaunchBench);
