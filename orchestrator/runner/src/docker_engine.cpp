#include "swarmbox/runner/docker_engine.hpp"

#include <chrono>
#include <thread>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <set>
#include <sstream>

#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/docker/tar_archive.hpp"
#include "swarmbox/runner/end_matcher.hpp"

namespace swarmbox::runner {

namespace fs = std::filesystem;
using dsl::Verdict;

struct DockerEngine::Follower {
  docker::CancelToken cancel;
  std::thread thread;
  std::atomic<bool> done{false};
  std::atomic<bool> clean_end{false};  // the stream ended by itself: the container's output closed
  std::atomic<std::uint64_t> lines{0};
};

// The second half of a container's stop, finished while the tree goes on: Docker's stop call
// returns only after the engine has torn down the container's network (~0.1-0.4 s each, one at a
// time inside the engine), then the exit code, artifacts and removal.
struct DockerEngine::PendingStop {
  std::thread thread;
  bool stop_returned = false;  // guarded by DockerEngine::done_mu_
  std::promise<void> logs_joined;
  Verdict verdict;  // written by `thread`, read after joining it
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
    : api_(api), hub_(hub), clock_(clock), options_(std::move(options)) {
  std::error_code ec;
  fs::create_directories(fs::path(options_.trial_dir) / "logs", ec);
}

DockerEngine::~DockerEngine() {
  CloseQueue();
  JoinStops();
  for (auto& [component, f] : followers_) f->cancel.Cancel();
  for (auto& [component, f] : followers_) {
    if (f->thread.joinable()) f->thread.join();
  }
}

void DockerEngine::Trace(const dsl::Component& component, dsl::EventKind event,
                         const Verdict& verdict) {
  if (event == dsl::EventKind::kBuild) {
    // A container's creation running ahead traces its build itself, once it has finished.
    std::lock_guard lock(mu_);
    if (build_traced_by_create_.erase(component.id()) > 0) return;
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

void DockerEngine::Enqueue(std::function<void(bool)> job) {
  std::unique_lock lock(queue_mu_);
  if (closing_) {
    lock.unlock();
    job(true);
    return;
  }
  jobs_.push_back(std::move(job));
  if (idle_workers_ == 0 && static_cast<int>(workers_.size()) < options_.max_parallel) {
    workers_.emplace_back([this] {
      std::unique_lock worker_lock(queue_mu_);
      while (true) {
        ++idle_workers_;
        queue_cv_.wait(worker_lock, [this] { return closing_ || !jobs_.empty(); });
        --idle_workers_;
        if (jobs_.empty()) return;  // closing
        std::function<void(bool)> next = std::move(jobs_.front());
        jobs_.pop_front();
        const bool cancelled = closing_;
        worker_lock.unlock();
        next(cancelled);
        worker_lock.lock();
      }
    });
  } else {
    queue_cv_.notify_one();
  }
}

void DockerEngine::CloseQueue() {
  std::vector<std::thread> workers;
  {
    std::lock_guard lock(queue_mu_);
    closing_ = true;
    workers.swap(workers_);
  }
  queue_cv_.notify_all();
  for (std::thread& t : workers) t.join();
}

std::optional<Verdict> DockerEngine::WaitCreated(const std::string& component) {
  std::shared_future<Verdict> created;
  {
    std::lock_guard lock(mu_);
    auto it = creates_.find(component);
    if (it == creates_.end()) return std::nullopt;
    created = it->second;
  }
  return created.get();
}

void DockerEngine::FinishCreates() {
  std::vector<std::shared_future<Verdict>> all;
  {
    std::lock_guard lock(mu_);
    for (const auto& [component, created] : creates_) all.push_back(created);
  }
  for (const auto& created : all) created.wait();
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
  JoinStops();  // a rebuild: the containers of the last build are gone first
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
  JoinStops();  // its containers are removed first
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

namespace {

// The volume a path lies under ("" = none): Docker's archive endpoint writes into a read-only
// container only there ("container rootfs is marked read-only" elsewhere; a tmpfs is not mounted
// before the start, so what is put there is hidden once it runs).
std::string VolumeOf(const dsl::ContainerSpec& spec, const std::string& path) {
  for (const std::string& v : spec.volumes) {
    const std::string prefix = !v.empty() && v.back() == '/' ? v : v + "/";
    if (path.rfind(prefix, 0) == 0) return v;
  }
  return {};
}

}  // namespace

Status DockerEngine::CopyInputs(const dsl::ContainerSpec& spec, const std::string& container_id) {
  if (spec.inputs.empty() && spec.scratch_dirs.empty()) return Ok{};
  // One archive per destination: "/" for a writable root filesystem, else each volume.
  struct Archive {
    docker::TarWriter tar;
    std::set<std::string> dirs;
  };
  std::map<std::string, Archive> archives;
  auto archive_for = [&](const std::string& path, std::string* relative) -> Result<Archive*> {
    std::string dest = "/";
    if (spec.read_only_rootfs) {
      dest = VolumeOf(spec, path);
      if (dest.empty()) {
        return Error(ErrorCode::kInvalidArgument,
                     "the root filesystem is read-only and " + path + " lies in none of its volumes");
      }
    }
    *relative = fs::path(path).lexically_relative(dest).string();
    return &archives[dest];
  };
  auto add_parents = [](Archive& a, const std::string& relative) -> Status {
    std::vector<std::string> chain;
    for (fs::path p = fs::path(relative).parent_path(); !p.empty(); p = p.parent_path()) {
      chain.push_back(p.string());
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      if (a.dirs.insert(*it).second) SWARMBOX_TRY(a.tar.AddDirectory(*it, 0755));
    }
    return Ok{};
  };
  for (const std::string& dir : spec.scratch_dirs) {
    std::string relative;
    auto a = archive_for(dir, &relative);
    if (!a) return a.error();
    SWARMBOX_TRY(add_parents(**a, relative));
    if ((*a)->dirs.insert(relative).second) SWARMBOX_TRY((*a)->tar.AddDirectory(relative, 01777));
  }
  for (const dsl::InputFile& in : spec.inputs) {
    std::ifstream f(in.host_path, std::ios::binary);
    if (!f) return Error(ErrorCode::kNotFound, "cannot read input file", in.host_path);
    std::ostringstream content;
    content << f.rdbuf();
    std::string relative;
    auto a = archive_for(in.container_path, &relative);
    if (!a) return a.error();
    SWARMBOX_TRY(add_parents(**a, relative));
    SWARMBOX_TRY((*a)->tar.AddFile(relative, content.str(), 0644));
  }
  for (auto& [dest, a] : archives) {
    auto bytes = a.tar.Finish();
    if (!bytes) return bytes.error();
    SWARMBOX_TRY(api_.PutArchive(container_id, dest, *bytes));
  }
  return Ok{};
}

Verdict DockerEngine::CreateContainer(dsl::Plugin& plugin) {
  if (options_.max_parallel <= 1) return CreateNow(plugin);
  const std::string component = plugin.id();
  // What can be checked now is checked now: the tree's Build walk fails where it did before.
  const dsl::ContainerSpec& s = plugin.spec();
  std::optional<std::shared_future<Verdict>> owner;
  {
    std::lock_guard lock(mu_);
    for (const dsl::Attachment& a : s.networks) {
      if (network_ids_.count(a.network) == 0) {
        return Verdict::Err("network '" + a.network + "' of " + component + " was not created",
                            plugin.Path());
      }
    }
    if (!s.network_of.empty()) {
      auto it = creates_.find(s.network_of);
      if (it != creates_.end()) owner = it->second;
    }
  }
  auto promise = std::make_shared<std::promise<Verdict>>();
  const int priority = plugin.run_priority();
  {
    std::lock_guard lock(mu_);
    creates_[component] = promise->get_future().share();
    build_traced_by_create_.insert(component);
    ++unfinished_creates_[priority];
  }
  // What a creation waits for (the earlier levels' creations, the owner of a shared network
  // namespace) was queued before it: workers take jobs in order, so it is running or done and
  // the wait cannot starve the queue.
  Enqueue([this, &plugin, promise, owner, priority](bool cancelled) {
    if (!cancelled) {
      std::unique_lock lock(mu_);
      create_cv_.wait(lock, [&] {
        for (const auto& [p, n] : unfinished_creates_) {
          if (p < priority && n > 0) return false;
        }
        return true;
      });
    }
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
    {
      std::lock_guard lock(mu_);
      --unfinished_creates_[priority];
    }
    create_cv_.notify_all();
    promise->set_value(v);
  });
  return Verdict::Success();
}

Verdict DockerEngine::CreateNow(dsl::Plugin& plugin) {
  const dsl::ContainerSpec& s = plugin.spec();
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
  std::unique_lock lock(mu_);
  if (!s.network_of.empty()) {
    auto owner = container_ids_.find(s.network_of);
    if (owner == container_ids_.end()) {
      return Verdict::Err("the network namespace of " + plugin.id() + " belongs to '" + s.network_of +
                              "', which was not created",
                          plugin.Path());
    }
    if (!s.networks.empty() || !s.hostname.empty()) {
      return Verdict::Err(plugin.id() + " shares the network of " + s.network_of +
                              ": it can have no networks or hostname of its own",
                          plugin.Path());
    }
    spec.network_mode = "container:" + owner->second;
  }
  if (s.no_network) {
    if (!s.networks.empty() || !s.network_of.empty()) {
      return Verdict::Err(plugin.id() + " has no network: it can join none", plugin.Path());
    }
    spec.network_mode = "none";
  }
  for (const dsl::Attachment& a : s.networks) {
    auto it = network_ids_.find(a.network);
    if (it == network_ids_.end()) {
      return Verdict::Err("network '" + a.network + "' of " + plugin.id() + " was not created",
                          plugin.Path());
    }
    spec.networks.push_back({it->second, a.ipv4, a.aliases});
  }
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
  if (Status st = CopyInputs(s, *id); !st) {
    return Verdict::FromError(st.error().Context("copying input files into " + s.name),
                              plugin.Path());
  }
  return Verdict::Success();
}

void DockerEngine::StartFollower(const std::string& component, const std::string& container_id,
                                 std::uint64_t skip_lines) {
  JoinFollower(component, /*cancel=*/true);
  auto f = std::make_unique<Follower>();
  Follower* raw = f.get();
  std::uint64_t generation = 0;
  {
    std::lock_guard lock(mu_);
    generation = next_generation_++;
    generations_[component] = generation;
  }
  const std::string path = (fs::path(options_.trial_dir) / "logs" / (component + ".log")).string();
  raw->thread = std::thread([this, raw, component, container_id, path, generation, skip_lines] {
    std::uint64_t to_skip = skip_lines;
    std::FILE* out = std::fopen(path.c_str(), "ab");
    docker::LogOptions opts;
    opts.follow = true;
    Status s = api_.FollowLogs(
        container_id, opts,
        [&](const docker::LogLine& line) {
          if (to_skip > 0) {  // delivered by an earlier follower (the container ran before)
            --to_skip;
            return;
          }
          if (out != nullptr) {
            std::fwrite(line.text.data(), 1, line.text.size(), out);
            std::fputc('\n', out);
            std::fflush(out);
          }
          raw->lines.fetch_add(1);
          hub_.Push({HubItem::Kind::kLine, component, line.text,
                     clock_.NowS() - options_.start_wall_s, generation});
        },
        &raw->cancel);
    if (out != nullptr) std::fclose(out);
    std::string why;
    if (!s && s.error().code() != ErrorCode::kCancelled) why = s.error().ToString();
    if (out == nullptr) why = "cannot write " + path;
    hub_.Push({HubItem::Kind::kStreamEnd, component, why, clock_.NowS() - options_.start_wall_s,
               generation});
    raw->clean_end.store(s.ok());
    {
      std::lock_guard lock(done_mu_);
      raw->done.store(true);
    }
    done_cv_.notify_all();
  });
  std::lock_guard lock(mu_);
  followers_[component] = std::move(f);
}

void DockerEngine::JoinFollower(const std::string& component, bool cancel) {
  std::unique_ptr<Follower> follower;
  {
    std::lock_guard lock(mu_);
    auto it = followers_.find(component);
    if (it == followers_.end()) return;
    follower = std::move(it->second);
    followers_.erase(it);
  }
  Follower& f = *follower;
  if (!cancel) {
    // The stream ends by itself once the container stopped; give it a moment to deliver the rest.
    const auto deadline = std::chrono::steady_clock::now() + kStreamEndGrace;
    while (!f.done.load() && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  f.cancel.Cancel();
  if (f.thread.joinable()) f.thread.join();
  std::lock_guard lock(mu_);
  reports_[component].log_lines += f.lines.load();
}

Status DockerEngine::ResumeLogs(const std::string& component) {
  auto id = ContainerId(component);
  if (!id) return Error(ErrorCode::kNotFound, "no container for component " + component);
  JoinFollower(component, /*cancel=*/true);  // counts its lines into the report
  std::uint64_t delivered = 0;
  {
    std::lock_guard lock(mu_);
    delivered = reports_[component].log_lines;
  }
  // Lines the cancelled stream had not delivered yet come again with the new one.
  StartFollower(component, *id, delivered);
  return Ok{};
}

bool DockerEngine::IsCurrent(const HubItem& item) const {
  std::lock_guard lock(mu_);
  auto it = generations_.find(item.component);
  return it != generations_.end() && it->second == item.generation;
}

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

void DockerEngine::CollectArtifacts(const std::string& component,
                                    const std::vector<std::string>& artifacts,
                                    const std::string& artifacts_dir,
                                    const std::string& container_id) {
  const fs::path dest_dir = fs::path(options_.trial_dir) / artifacts_dir;
  if (!artifacts_dir.empty() && !artifacts.empty()) {
    std::error_code ec;
    fs::create_directories(dest_dir, ec);
    if (ec) {
      AddProblem(component + ": cannot create " + dest_dir.string() + ": " + ec.message());
      return;
    }
  }
  for (const std::string& path : artifacts) {
    auto tar = api_.GetArchive(container_id, path);
    if (!tar) {
      AddProblem(component + ": artifact " + path + " not collected: " + tar.error().ToString());
      continue;
    }
    auto entries = docker::ReadTar(*tar);
    if (!entries) {
      AddProblem(component + ": artifact " + path + " unreadable: " + entries.error().ToString());
      continue;
    }
    for (const docker::TarEntry& e : *entries) {
      if (e.type != docker::TarEntry::Type::kFile) continue;
      // The trial folder keeps file names (truth.csv); an artifacts_dir keeps a folder's layout.
      const fs::path relative = fs::path(e.path).lexically_normal();
      if (relative.empty() || relative.is_absolute() || *relative.begin() == "..") continue;
      const std::string name = artifacts_dir.empty() ? relative.filename().string()
                                                     : (fs::path(artifacts_dir) / relative).string();
      if (!artifacts_dir.empty() && relative.has_parent_path()) {
        std::error_code ec;
        fs::create_directories(dest_dir / relative.parent_path(), ec);
      }
      const std::string dest = artifacts_dir.empty() ? (fs::path(options_.trial_dir) / name).string()
                                                     : (dest_dir / relative).string();
      std::ofstream out(dest, std::ios::binary | std::ios::trunc);
      out.write(e.content.data(), static_cast<std::streamsize>(e.content.size()));
      if (!out) {
        AddProblem(component + ": cannot write " + dest);
        continue;
      }
      std::lock_guard lock(mu_);
      artifacts_[name] = dest;
    }
  }
}

Verdict DockerEngine::StopContainer(dsl::Plugin& plugin) {
  const std::string component = plugin.id();
  (void)WaitCreated(component);  // a creation still under way finishes first, then goes
  std::string id;
  {
    std::lock_guard lock(mu_);
    creates_.erase(component);
    auto it = container_ids_.find(component);
    if (it == container_ids_.end()) return Verdict::Success();
    id = it->second;
    container_ids_.erase(it);  // a rebuild may create the component again while this one goes
  }
  auto pending = std::make_unique<PendingStop>();
  PendingStop* raw = pending.get();
  std::shared_future<void> logs_joined = raw->logs_joined.get_future().share();
  raw->thread = std::thread([this, raw, logs_joined, id, component, name = plugin.spec().name,
                             path = plugin.Path(), grace_s = plugin.spec().stop_timeout_s,
                             artifacts = plugin.spec().artifacts,
                             artifacts_dir = plugin.spec().artifacts_dir] {
    // SIGTERM, SIGKILL after the grace; returns once the engine has cleaned the container up.
    Status s = api_.StopContainer(id, grace_s);
    if (!s && s.error().code() != ErrorCode::kNotFound) {
      raw->verdict.KeepWorse(Verdict::FromError(s.error().Context("stopping " + name), path));
    }
    {
      std::lock_guard lock(done_mu_);
      raw->stop_returned = true;
    }
    done_cv_.notify_all();
    logs_joined.wait();  // the log is complete: the container may go
    if (auto info = api_.InspectContainer(id)) {
      std::lock_guard lock(mu_);
      reports_[component].exit_code = info->state.exit_code;
      reports_[component].oom_killed = info->state.oom_killed;
    }
    CollectArtifacts(component, artifacts, artifacts_dir, id);
    if (Status r = api_.RemoveContainer(id, /*force=*/true, /*remove_volumes=*/true);
        !r && r.error().code() != ErrorCode::kNotFound) {
      raw->verdict.KeepWorse(Verdict::FromError(r.error().Context("removing " + name), path));
    }
  });
  // The container counts as stopped once its program has exited: its log stream ends by itself
  // (its output closed). A stream that broke, or a container without one, waits for Docker's stop.
  {
    std::unique_lock lock(done_mu_);
    done_cv_.wait(lock, [&] { return raw->stop_returned || LogEndedByItself(component); });
  }
  JoinFollower(component, /*cancel=*/false);
  raw->logs_joined.set_value();
  std::lock_guard lock(mu_);
  pending_stops_.push_back(std::move(pending));
  return Verdict::Success();
}

bool DockerEngine::LogEndedByItself(const std::string& component) const {
  std::lock_guard lock(mu_);
  auto it = followers_.find(component);
  return it != followers_.end() && it->second->done.load() && it->second->clean_end.load();
}

void DockerEngine::JoinStops() {
  // One joiner at a time: a second caller (the other network of the level) returns only once the
  // first has joined everything.
  std::lock_guard joining(join_mu_);
  std::vector<std::unique_ptr<PendingStop>> pending;
  {
    std::lock_guard lock(mu_);
    pending.swap(pending_stops_);
  }
  Verdict v;
  for (auto& p : pending) {
    if (p->thread.joinable()) p->thread.join();
    v.KeepWorse(p->verdict);
  }
  std::lock_guard lock(mu_);
  stops_verdict_.KeepWorse(v);
}

Verdict DockerEngine::FinishStops() {
  JoinStops();
  std::lock_guard lock(mu_);
  Verdict v = stops_verdict_;
  stops_verdict_ = Verdict::Success();
  return v;
}

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
