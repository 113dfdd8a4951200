#include "swarmbox/runner/docker_engine.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <thread>

#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/runner/container_files.hpp"
#include "swarmbox/runner/end_matcher.hpp"

namespace swarmbox::runner {

namespace fs = std::filesystem;
using dsl::Verdict;

// What the second half of a stop needs, copied out of the plugin (the tree may go on).
struct DockerEngine::StopRequest {
  std::string id;         // Docker's
  std::string component;
  std::string name;       // the container's
  std::string path;       // the plugin's, for verdicts
  int grace_s = 0;
  std::vector<std::string> artifacts;
  std::string artifacts_dir;
};

namespace {

constexpr auto kStreamEndGrace = std::chrono::seconds(5);

bool IsSubnetConflict(const Error& e) {
  const std::string& m = e.message();
  return m.find("overlap") != std::string::npos || m.find("Pool overlaps") != std::string::npos;
}

}  // namespace

Verdict RunConcurrently(const std::vector<std::function<Verdict()>>& steps, int max_threads) {
  std::vector<Verdict> verdicts(steps.size());
  const std::size_t threads =
      std::min(steps.size(), static_cast<std::size_t>(std::max(1, max_threads)));
  if (threads <= 1) {
    for (std::size_t i = 0; i < steps.size(); ++i) verdicts[i] = steps[i]();
  } else {
    std::atomic<std::size_t> next{0};
    auto work = [&] {
      for (std::size_t i = next.fetch_add(1); i < steps.size(); i = next.fetch_add(1)) {
        verdicts[i] = steps[i]();
      }
    };
    std::vector<std::thread> pool;
    pool.reserve(threads - 1);
    for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(work);
    work();  // the calling thread is one of the workers
    for (std::thread& t : pool) t.join();
  }
  Verdict v;
  for (const Verdict& one : verdicts) v.KeepWorse(one);  // in step order: ties keep the first
  return v;
}

DockerEngine::DockerEngine(docker::DockerApi& api, LogHub& hub, Clock& clock,
                           EngineOptions options)
    : api_(api),
      hub_(hub),
      clock_(clock),
      options_(std::move(options)),
      followers_(api, hub, clock,
                 {(fs::path(options_.trial_dir) / "logs").string(), options_.start_wall_s,
                  [this] { NotifyEnded(); }}),
      create_workers_(options_.max_parallel) {
  std::error_code ec;
  fs::create_directories(fs::path(options_.trial_dir) / "logs", ec);
}

DockerEngine::~DockerEngine() {
  create_workers_.Close();
  stops_.Join();
  // followers_ cancels and joins the followers still running as it goes.
}

void DockerEngine::Trace(const dsl::Component& component, dsl::EventKind event,
                         const Verdict& verdict) {
  if (event == dsl::EventKind::kBuild) {
    // A container's creation running ahead traces its build itself, once it has finished.
    if (creates_.TakeBuildTrace(component.id())) return;
  }
  std::lock_guard lock(trace_mu_);
  if (options_.on_trace) options_.on_trace(component, event, verdict);
}

Verdict DockerEngine::RunSiblings(const std::vector<std::function<Verdict()>>& steps,
                                  bool stop_on_failure) {
  // Stops (the only walk that goes on after a failure) mostly wait for programs to exit: all of
  // a level's at once, so every container gets its SIGTERM right away.
  const bool stopping = !stop_on_failure;
  const int threads = stopping && options_.max_parallel > 1
                          ? std::max(options_.max_parallel, static_cast<int>(steps.size()))
                          : options_.max_parallel;
  return RunConcurrently(steps, threads);
}

std::optional<Verdict> DockerEngine::WaitCreated(const std::string& component) {
  auto created = creates_.Find(component);
  if (!created) return std::nullopt;
  return created->get();
}

void DockerEngine::FinishCreates() {
  for (const auto& created : creates_.All()) created.wait();
}

void DockerEngine::AddProblem(std::string problem) {
  std::lock_guard lock(mu_);
  problems_.push_back(std::move(problem));
}

std::optional<std::string> DockerEngine::ContainerId(const std::string& component) const {
  std::lock_guard lock(mu_);
  auto it = container_ids_.find(component);
  if (it == container_ids_.end()) return std::nullopt;
  return it->second;
}

Verdict DockerEngine::CreateNetwork(dsl::Network& network) {
  stops_.Join();  // a rebuild: the containers of the last build are gone first
  const dsl::NetworkSpec& s = network.spec();
  docker::NetworkSpec spec;
  spec.name = s.name;
  spec.subnet = s.subnet;
  spec.gateway = s.gateway;
  spec.internal = s.internal;
  spec.labels = s.labels;
  auto id = api_.CreateNetwork(spec);
  if (!id) {
    if (IsSubnetConflict(id.error())) subnet_conflict_.store(true);
    return Verdict::FromError(id.error().Context("creating network " + s.name + " (" + s.subnet + ")"),
                              network.Path());
  }
  std::lock_guard lock(mu_);
  network_ids_[network.id()] = *id;
  return Verdict::Success();
}

Verdict DockerEngine::RemoveNetwork(dsl::Network& network) {
  stops_.Join();  // its containers are removed first
  std::string id;
  {
    std::lock_guard lock(mu_);
    auto it = network_ids_.find(network.id());
    if (it == network_ids_.end()) return Verdict::Success();
    id = it->second;
    network_ids_.erase(it);
  }
  const Status s = docker::RemoveNetworkPatiently(api_, id);
  if (docker::IsStaleEndpointRefusal(s)) {
    // An engine fault after the trial, not the trial's: its outcome stands, the problem is kept.
    AddProblem("network " + network.spec().name + " left on the engine: " + s.error().message() +
               " (" + docker::kStaleEndpointAdvice + ")");
    return Verdict::Success();
  }
  if (!s && s.error().code() != ErrorCode::kNotFound) {
    return Verdict::FromError(s.error().Context("removing network " + network.spec().name),
                              network.Path());
  }
  return Verdict::Success();
}

Verdict DockerEngine::CreateContainer(dsl::Plugin& plugin) {
  if (options_.max_parallel <= 1) return CreateNow(plugin);
  const std::string component = plugin.id();
  // What can be checked now is checked now: the tree's Build walk fails where it did before.
  const dsl::ContainerSpec& s = plugin.spec();
  {
    std::lock_guard lock(mu_);
    for (const dsl::Attachment& a : s.networks) {
      if (network_ids_.count(a.network) == 0) {
        return Verdict::Err("network '" + a.network + "' of " + component + " was not created",
                            plugin.Path());
      }
    }
  }
  std::optional<std::shared_future<Verdict>> owner;
  if (!s.network_of.empty()) owner = creates_.Find(s.network_of);
  const int priority = plugin.run_priority();
  auto promise = creates_.Add(component, priority);
  // What a creation waits for (the earlier levels' creations, the owner of a shared network
  // namespace) was queued before it: workers take jobs in order, so it is running or done and
  // the wait cannot starve the queue.
  create_workers_.Post([this, &plugin, promise, owner, priority](bool cancelled) {
    CreateAhead(plugin, priority, cancelled, owner, promise);
  });
  return Verdict::Success();
}

void DockerEngine::CreateAhead(dsl::Plugin& plugin, int priority, bool cancelled,
                               const std::optional<std::shared_future<Verdict>>& owner,
                               const std::shared_ptr<std::promise<Verdict>>& promise) {
  if (!cancelled) creates_.WaitForEarlierLevels(priority);
  Verdict v;
  if (cancelled) {
    v = Verdict::Err("not created: the run was torn down first", plugin.Path());
  } else if (owner && !owner->get().ok()) {
    v = Verdict::Err("the network namespace of " + plugin.id() + " belongs to '" +
                         plugin.spec().network_of + "', which was not created",
                     plugin.Path());
  } else {
    v = CreateNow(plugin);
  }
  {
    std::lock_guard lock(trace_mu_);
    if (options_.on_trace) options_.on_trace(plugin, dsl::EventKind::kBuild, v);
  }
  creates_.Finished(priority, promise, v);
}

namespace {

// The plugin's container as the Docker API creates it, networks aside.
docker::ContainerSpec ContainerSpecOf(const dsl::ContainerSpec& s) {
  docker::ContainerSpec spec;
  spec.name = s.name;
  spec.image = s.image;
  if (s.argv_is_cmd) {
    spec.cmd = s.argv;  // the image's ENTRYPOINT stays (a user's image)
  } else if (!s.argv.empty()) {
    spec.entrypoint = {s.argv.front()};
    spec.cmd.assign(s.argv.begin() + 1, s.argv.end());
  }
  spec.env = s.env;
  spec.labels = s.labels;
  spec.user = s.user;
  spec.hostname = s.hostname;
  spec.stop_timeout_s = s.stop_timeout_s;
  spec.auto_remove = false;  // a crashed container keeps its logs until we collected them
  spec.cap_add = s.cap_add;
  spec.cap_drop = s.cap_drop;
  for (const dsl::ContainerSpec::Port& p : s.ports) spec.ports.push_back({p.container_port, p.host_ip, p.host_port});
  if (s.no_new_privileges) spec.security_opt.push_back("no-new-privileges");
  spec.read_only_rootfs = s.read_only_rootfs;
  for (const std::string& v : s.volumes) {
    spec.mounts.push_back({docker::Mount::Type::kVolume, "", v, false, 0, 0});  // anonymous
  }
  for (const dsl::TmpfsMount& t : s.tmpfs) {
    spec.mounts.push_back({docker::Mount::Type::kTmpfs, "", t.path, false, t.size_mib << 20, 01777});
  }
  spec.resources.memory_bytes = s.memory_mib << 20;
  spec.resources.pids_limit = s.pids_limit;
  return spec;
}

// The network mode and networks of *spec from the containers and networks created so far
// (component id -> Docker id); a verdict when the plugin names one that was not created or
// combines them wrongly.
std::optional<Verdict> AttachNetworks(const dsl::Plugin& plugin, const std::map<std::string, std::string>& container_ids,
                                      const std::map<std::string, std::string>& network_ids,
                                      docker::ContainerSpec* spec) {
  const dsl::ContainerSpec& s = plugin.spec();
  if (!s.network_of.empty()) {
    auto owner = container_ids.find(s.network_of);
    if (owner == container_ids.end()) {
      return Verdict::Err("the network namespace of " + plugin.id() + " belongs to '" + s.network_of +
                              "', which was not created",
                          plugin.Path());
    }
    if (!s.networks.empty() || !s.hostname.empty()) {
      return Verdict::Err(plugin.id() + " shares the network of " + s.network_of +
                              ": it can have no networks or hostname of its own",
                          plugin.Path());
    }
    spec->network_mode = "container:" + owner->second;
  }
  if (s.no_network) {
    if (!s.networks.empty() || !s.network_of.empty()) {
      return Verdict::Err(plugin.id() + " has no network: it can join none", plugin.Path());
    }
    spec->network_mode = "none";
  }
  for (const dsl::Attachment& a : s.networks) {
    auto it = network_ids.find(a.network);
    if (it == network_ids.end()) {
      return Verdict::Err("network '" + a.network + "' of " + plugin.id() + " was not created",
                          plugin.Path());
    }
    spec->networks.push_back({it->second, a.ipv4, a.aliases});
  }
  return std::nullopt;
}

}  // namespace

Verdict DockerEngine::CreateNow(dsl::Plugin& plugin) {
  const dsl::ContainerSpec& s = plugin.spec();
  docker::ContainerSpec spec = ContainerSpecOf(s);
  std::unique_lock lock(mu_);
  if (auto refused = AttachNetworks(plugin, container_ids_, network_ids_, &spec)) return *refused;
  lock.unlock();
  auto id = api_.CreateContainer(spec);
  if (!id) {
    return Verdict::FromError(id.error().Context("creating container " + s.name), plugin.Path());
  }
  lock.lock();
  container_ids_[plugin.id()] = *id;
  reports_[plugin.id()] = ComponentReport{plugin.id(), std::nullopt, false,
                                          "logs/" + plugin.id() + ".log", 0};
  lock.unlock();
  if (Status st = CopyInputs(api_, s, *id); !st) {
    return Verdict::FromError(st.error().Context("copying input files into " + s.name),
                              plugin.Path());
  }
  return Verdict::Success();
}

void DockerEngine::StartFollower(const std::string& component, const std::string& container_id,
                                 std::uint64_t skip_lines) {
  CountLines(component, followers_.Start(component, container_id, skip_lines));
}

void DockerEngine::CountLines(const std::string& component, std::uint64_t lines) {
  if (lines == 0) return;
  std::lock_guard lock(mu_);
  reports_[component].log_lines += lines;
}

void DockerEngine::NotifyEnded() {
  { std::lock_guard lock(ended_mu_); }  // a waiter checks its flags under the lock: none is missed
  ended_cv_.notify_all();
}

Status DockerEngine::ResumeLogs(const std::string& component) {
  auto id = ContainerId(component);
  if (!id) return Error(ErrorCode::kNotFound, "no container for component " + component);
  // Counts its lines into the report.
  CountLines(component, followers_.Finish(component, std::chrono::milliseconds(0)));
  std::uint64_t delivered = 0;
  {
    std::lock_guard lock(mu_);
    delivered = reports_[component].log_lines;
  }
  // Lines the cancelled stream had not delivered yet come again with the new one.
  StartFollower(component, *id, delivered);
  return Ok{};
}

bool DockerEngine::IsCurrent(const HubItem& item) const { return followers_.IsCurrent(item); }

Verdict DockerEngine::StartContainer(dsl::Plugin& plugin) {
  const dsl::ContainerSpec& s = plugin.spec();
  if (auto created = WaitCreated(plugin.id()); created && !created->ok()) return *created;
  const auto found = ContainerId(plugin.id());
  if (!found) return Verdict::Err("no container for " + plugin.id(), plugin.Path());
  const std::string id = *found;
  if (!s.ready_pattern.empty()) {
    auto re = CompileLogPattern(s.ready_pattern);
    if (!re) return Verdict::FromError(re.error(), plugin.Path());
    hub_.Expect(plugin.id(), std::move(*re));
  }
  if (Status st = api_.StartContainer(id); !st) {
    return Verdict::FromError(st.error().Context("starting " + s.name), plugin.Path());
  }
  StartFollower(plugin.id(), id);
  if (s.ready_pattern.empty()) return Verdict::Success();
  switch (hub_.WaitReady(plugin.id(), std::chrono::milliseconds(s.ready_timeout.ms()),
                         options_.interrupted)) {
    case LogHub::Readiness::kReady:
      return Verdict::Success();
    case LogHub::Readiness::kInterrupted:
      return Verdict::Err("interrupted while waiting for " + plugin.id() + " to be ready",
                          plugin.Path());
    case LogHub::Readiness::kTimedOut:
      return Verdict::Failure(plugin.id() + " did not log '" + s.ready_pattern + "' within " +
                                  s.ready_timeout.ToString(),
                              plugin.Path());
    case LogHub::Readiness::kStreamEnded: {
      auto state = api_.InspectContainer(id);
      std::string how = state ? "exited with code " + std::to_string(state->state.exit_code)
                              : "its log stream ended";
      return Verdict::Failure(plugin.id() + " " + how + " before it was ready", plugin.Path());
    }
  }
  return Verdict::Err("unreachable", plugin.Path());
}

Verdict DockerEngine::StopContainer(dsl::Plugin& plugin) {
  const std::string component = plugin.id();
  (void)WaitCreated(component);  // a creation still under way finishes first, then goes
  creates_.Forget(component);
  StopRequest request;
  {
    std::lock_guard lock(mu_);
    auto it = container_ids_.find(component);
    if (it == container_ids_.end()) return Verdict::Success();
    request.id = it->second;
    container_ids_.erase(it);  // a rebuild may create the component again while this one goes
  }
  const dsl::ContainerSpec& s = plugin.spec();
  request.component = component;
  request.name = s.name;
  request.path = plugin.Path();
  request.grace_s = s.stop_timeout_s;
  request.artifacts = s.artifacts;
  request.artifacts_dir = s.artifacts_dir;
  auto stop_returned = std::make_shared<std::atomic<bool>>(false);
  std::promise<void> log_joined;
  auto pending = detail::BackgroundStops::Launch(
      [this, request, stop_returned, log_complete = log_joined.get_future().share()] {
        return FinishStop(request, *stop_returned, log_complete);
      });
  // The container counts as stopped once its program has exited: its log stream ends by itself
  // (its output closed). A stream that broke, or a container without one, waits for Docker's stop.
  {
    std::unique_lock lock(ended_mu_);
    ended_cv_.wait(lock,
                   [&] { return stop_returned->load() || followers_.EndedByItself(component); });
  }
  CountLines(component, followers_.Finish(component, kStreamEndGrace));
  log_joined.set_value();
  stops_.Keep(std::move(pending));
  return Verdict::Success();
}

Verdict DockerEngine::FinishStop(const StopRequest& r, std::atomic<bool>& stop_returned,
                                 const std::shared_future<void>& log_complete) {
  Verdict v;
  // SIGTERM, SIGKILL after the grace; returns once the engine has cleaned the container up.
  Status s = api_.StopContainer(r.id, r.grace_s);
  if (!s && s.error().code() != ErrorCode::kNotFound) {
    v.KeepWorse(Verdict::FromError(s.error().Context("stopping " + r.name), r.path));
  }
  stop_returned.store(true);
  NotifyEnded();
  log_complete.wait();  // the log is complete: the container may go
  if (auto info = api_.InspectContainer(r.id)) {
    std::lock_guard lock(mu_);
    reports_[r.component].exit_code = info->state.exit_code;
    reports_[r.component].oom_killed = info->state.oom_killed;
  }
  CollectedArtifacts collected =
      CollectArtifacts(api_, r.id, r.component, r.artifacts, options_.trial_dir, r.artifacts_dir);
  {
    std::lock_guard lock(mu_);
    problems_.insert(problems_.end(), collected.problems.begin(), collected.problems.end());
    for (auto& [name, dest] : collected.files) artifacts_[name] = dest;
  }
  if (Status rm = api_.RemoveContainer(r.id, /*force=*/true, /*remove_volumes=*/true);
      !rm && rm.error().code() != ErrorCode::kNotFound) {
    v.KeepWorse(Verdict::FromError(rm.error().Context("removing " + r.name), r.path));
  }
  return v;
}

Verdict DockerEngine::FinishStops() { return stops_.Take(); }

Result<docker::ContainerState> DockerEngine::Inspect(const std::string& component) {
  const auto id = ContainerId(component);
  if (!id) return Error(ErrorCode::kNotFound, "no container for component " + component);
  auto info = api_.InspectContainer(*id);
  // A container the kernel's OOM killer took exits 137 (SIGKILL), and Docker marks OOMKilled when
  // its OOM event arrives, which can be just after the exit is already visible (seen on 20.10 with
  // a 6 MiB agent: the first inspect said 137 and OOMKilled false). So a 137 without the mark is
  // asked again for up to ~1 s before it is taken as a plain SIGKILL.
  for (int retry = 0; retry < 10 && info && !info->state.running && info->state.exit_code == 137 &&
                      !info->state.oom_killed;
       ++retry) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    info = api_.InspectContainer(*id);
  }
  if (!info) return info.error();
  return info->state;
}

std::vector<ComponentReport> DockerEngine::Reports() const {
  std::lock_guard lock(mu_);
  std::vector<ComponentReport> out;
  for (const auto& [name, r] : reports_) out.push_back(r);
  return out;
}

}  // namespace swarmbox::runner
