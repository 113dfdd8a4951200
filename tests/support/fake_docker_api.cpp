#include "support/fake_docker_api.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <thread>

#include "swarmbox/docker/tar_archive.hpp"

namespace swarmbox::testing {

Error FakeDockerApi::NotModelled(std::string_view what) {
  return Error(ErrorCode::kInternal, std::string(what) + " is not modelled by FakeDockerApi");
}

bool FakeDockerApi::Selects(const docker::LabelSelector& selector, const docker::Labels& labels) {
  for (const auto& [k, v] : selector.equals) {
    auto it = labels.find(k);
    if (it == labels.end() || (!v.empty() && it->second != v)) return false;
  }
  return true;
}

Status FakeDockerApi::Record(const std::string& call) {
  calls_.push_back(call);
  if (fail.count(call) != 0) return Error(ErrorCode::kInvalidArgument, "container is not running", "fake");
  return Ok{};
}

std::string FakeDockerApi::AddRunning(const std::string& name) {
  std::lock_guard lock(mu_);
  const std::string id = "c" + std::to_string(next_id_++);
  Container c;
  c.spec.name = name;
  c.component = name;
  c.starts = 1;
  c.state.status = "running";
  c.state.running = true;
  containers_[id] = c;
  return id;
}

FakeDockerApi::Container* FakeDockerApi::Find(std::string_view id) {
  for (auto& [cid, c] : containers_) {
    if (cid == id || c.spec.name == id) return &c;
  }
  return nullptr;
}

std::vector<std::string> FakeDockerApi::Calls() const {
  std::lock_guard lock(mu_);
  return calls_;
}
std::vector<docker::ContainerSpec> FakeDockerApi::Created() const {
  std::lock_guard lock(mu_);
  return created_;
}
std::map<std::string, FakeDockerApi::Container> FakeDockerApi::Containers() const {
  std::lock_guard lock(mu_);
  return containers_;
}
std::map<std::string, docker::NetworkSpec> FakeDockerApi::Networks() const {
  std::lock_guard lock(mu_);
  return networks_;
}
std::map<std::string, std::string> FakeDockerApi::PutArchives() const {
  std::lock_guard lock(mu_);
  return put_archives_;
}
std::map<std::string, std::string> FakeDockerApi::PutArchiveDirs() const {
  std::lock_guard lock(mu_);
  return put_archive_dirs_;
}
std::vector<std::string> FakeDockerApi::SubnetsTried() const {
  std::lock_guard lock(mu_);
  return subnets_tried_;
}

Result<std::string> FakeDockerApi::Ping() { return std::string("1.41"); }
Result<docker::EngineVersion> FakeDockerApi::Version() {
  // A fixed engine, as GET /version of Debian 12's docker.io answers (for provenance).
  return docker::EngineVersion{"20.10.24+dfsg1", "1.41", "1.12", "linux", "amd64", "6.1.0-fake-amd64"};
}
Result<docker::BuildResult> FakeDockerApi::BuildImage(const docker::BuildRequest&,
                                                      const docker::BuildProgressFn&,
                                                      docker::CancelToken*) {
  return NotModelled("BuildImage");
}
Result<docker::ImageInfo> FakeDockerApi::InspectImage(std::string_view) { return NotModelled("InspectImage"); }
Result<std::vector<docker::ImageInfo>> FakeDockerApi::ListImages(const docker::LabelSelector&) {
  return NotModelled("ListImages");
}
Status FakeDockerApi::RemoveImage(std::string_view, bool) { return NotModelled("RemoveImage"); }

Result<std::string> FakeDockerApi::CreateNetwork(const docker::NetworkSpec& spec) {
  std::lock_guard lock(mu_);
  if (Status f = Record("create-network " + spec.name); !f) return f.error();
  subnets_tried_.push_back(spec.subnet);
  if (network_conflicts > 0) {
    --network_conflicts;
    return Error(ErrorCode::kInvalidArgument, "Pool overlaps with other one on this address space",
                 "POST /networks/create");
  }
  for (const auto& [id, n] : networks_) {
    if (n.name == spec.name) return Error(ErrorCode::kAlreadyExists, "network with name exists");
    if (n.subnet == spec.subnet) {
      return Error(ErrorCode::kInvalidArgument, "Pool overlaps with other one on this address space");
    }
  }
  const std::string id = "net" + std::to_string(next_id_++);
  networks_[id] = spec;
  return id;
}

Result<docker::NetworkInfo> FakeDockerApi::InspectNetwork(std::string_view) {
  return NotModelled("InspectNetwork");
}

Result<std::vector<docker::NetworkInfo>> FakeDockerApi::ListNetworks(
    const docker::LabelSelector& selector) {
  std::lock_guard lock(mu_);
  std::vector<docker::NetworkInfo> out;
  for (const auto& [id, n] : networks_) {
    if (!Selects(selector, n.labels)) continue;
    docker::NetworkInfo info;
    info.id = id;
    info.name = n.name;
    info.subnet = n.subnet;
    info.gateway = n.gateway;
    info.internal = n.internal;
    info.labels = n.labels;
    out.push_back(info);
  }
  return out;
}

Status FakeDockerApi::ConnectNetwork(const docker::EndpointSpec&, std::string_view) {
  return NotModelled("ConnectNetwork");
}
Status FakeDockerApi::DisconnectNetwork(std::string_view, std::string_view, bool) {
  return NotModelled("DisconnectNetwork");
}

Status FakeDockerApi::RemoveNetwork(std::string_view id) {
  std::lock_guard lock(mu_);
  auto it = networks_.find(std::string(id));
  if (it == networks_.end()) return Error(ErrorCode::kNotFound, "no such network");
  if (Status f = Record("remove-network " + it->second.name); !f) return f;
  if (stale_endpoints > 0) {
    --stale_endpoints;
    return Error(ErrorCode::kUnavailable,
                 "error while removing network: network " + it->second.name + " has active endpoints");
  }
  for (const auto& [cid, c] : containers_) {
    for (const auto& e : c.spec.networks) {
      if (e.network == id) {
        return Error(ErrorCode::kInvalidArgument, "network has active endpoints");
      }
    }
  }
  networks_.erase(it);
  return Ok{};
}

FakeDockerApi::InFlight::InFlight(FakeDockerApi& api, const std::string& kind) : api_(api), kind_(kind) {
  {
    std::lock_guard lock(api_.flight_mu_);
    const int now = ++api_.in_flight_[kind_];
    api_.max_in_flight_[kind_] = std::max(api_.max_in_flight_[kind_], now);
  }
  if (auto it = api_.latency.find(kind_); it != api_.latency.end()) std::this_thread::sleep_for(it->second);
}

FakeDockerApi::InFlight::~InFlight() {
  std::lock_guard lock(api_.flight_mu_);
  --api_.in_flight_[kind_];
}

std::map<std::string, int> FakeDockerApi::MaxInFlight() const {
  std::lock_guard lock(flight_mu_);
  return max_in_flight_;
}

Result<std::string> FakeDockerApi::CreateContainer(const docker::ContainerSpec& spec) {
  InFlight flight(*this, "create");
  std::unique_lock lock(mu_);
  if (auto label = spec.labels.find(std::string(docker::kLabelComponent)); label != spec.labels.end()) {
    const std::set<std::string> awaited = scripts[label->second].create_after_started;
    auto all_started = [&] {
      return std::all_of(awaited.begin(), awaited.end(), [&](const std::string& a) {
        return std::any_of(containers_.begin(), containers_.end(), [&](const auto& entry) {
          return entry.second.component == a && entry.second.starts > 0;
        });
      });
    };
    if (!cv_.wait_for(lock, std::chrono::seconds(10), all_started)) {
      return Error(ErrorCode::kTimeout, "create_after_started: created before the others started",
                   "POST /containers/create");
    }
  }
  if (Status f = Record("create " + spec.name); !f) return f.error();
  if (Find(spec.name) != nullptr) return Error(ErrorCode::kAlreadyExists, "name in use");
  if (auto label = spec.labels.find(std::string(docker::kLabelComponent));
      label != spec.labels.end() && scripts[label->second].fail_create) {
    return Error(ErrorCode::kInternal, "create refused (fail_create)", "POST /containers/create");
  }
  for (const auto& e : spec.networks) {
    if (networks_.count(e.network) == 0) return Error(ErrorCode::kNotFound, "no such network " + e.network);
  }
  if (spec.network_mode.rfind("container:", 0) == 0) {
    if (Find(spec.network_mode.substr(10)) == nullptr) {
      return Error(ErrorCode::kNotFound, "No such container: " + spec.network_mode.substr(10));
    }
    if (!spec.networks.empty() || !spec.hostname.empty()) {
      return Error(ErrorCode::kInvalidArgument, "conflicting options: networks/hostname and the network mode");
    }
  }
  const std::string id = "c" + std::to_string(next_id_++);
  created_.push_back(spec);
  Container c;
  c.spec = spec;
  auto label = spec.labels.find(std::string(docker::kLabelComponent));
  c.component = label == spec.labels.end() ? spec.name : label->second;
  c.state.status = "created";
  containers_[id] = c;
  cv_.notify_all();  // a log stream may be waiting for this container (log_after_created)
  return id;
}

Result<docker::ContainerInfo> FakeDockerApi::InspectContainer(std::string_view id) {
  std::lock_guard lock(mu_);
  Container* c = Find(id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  docker::ContainerInfo info;
  info.id = std::string(id);
  info.name = c->spec.name;
  info.state = c->state;
  info.labels = c->spec.labels;
  if (!c->state.running && c->state.status == "exited" && !c->exit_inspected) {
    c->exit_inspected = true;
    cv_.notify_all();  // a log stream may be waiting for this (log_after_exit_seen)
  }
  return info;
}

Result<std::vector<docker::ContainerSummary>> FakeDockerApi::ListContainers(
    const docker::LabelSelector& selector, bool all) {
  std::lock_guard lock(mu_);
  std::vector<docker::ContainerSummary> out;
  for (const auto& [id, c] : containers_) {
    if (!Selects(selector, c.spec.labels) || (!all && !c.state.running)) continue;
    docker::ContainerSummary s;
    s.id = id;
    s.names = {c.spec.name};
    s.state = c.state.status;
    s.labels = c.spec.labels;
    out.push_back(s);
  }
  return out;
}

bool FakeDockerApi::Rendezvous(std::unique_lock<std::mutex>& lock,
                               const std::set<std::string>& group, std::set<std::string>& arrived,
                               const std::string& component) {
  if (group.count(component) == 0) return true;
  arrived.insert(component);
  cv_.notify_all();
  return cv_.wait_for(lock, std::chrono::seconds(10), [&] {
    for (const std::string& g : group) {
      if (arrived.count(g) == 0) return false;
    }
    return true;
  });
}

Status FakeDockerApi::StartContainer(std::string_view id) {
  InFlight flight(*this, "start");
  std::unique_lock lock(mu_);
  Container* c = Find(id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  const std::string component = c->component;
  if (!Rendezvous(lock, start_together, started_together_, component)) {
    return Error(ErrorCode::kTimeout, component + " started alone", "POST /containers/start");
  }
  c = Find(id);  // the map may have changed while we waited
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  if (Status f = Record("start " + c->spec.name); !f) return f;
  if (scripts[c->component].fail_start) {
    return Error(ErrorCode::kInternal, "exec format error", "POST /containers/start");
  }
  if (c->spec.network_mode.rfind("container:", 0) == 0) {
    Container* owner = Find(c->spec.network_mode.substr(10));
    if (owner == nullptr || !owner->state.running) {
      return Error(ErrorCode::kInvalidArgument, "cannot join network of a non running container");
    }
  }
  if (!c->state.running) StartLocked(*c);
  cv_.notify_all();
  return Ok{};
}

void FakeDockerApi::StartLocked(Container& c) {
  const ContainerScript& s = scripts[c.component];
  const auto& lines = c.starts == 0 ? s.lines : s.restart_lines;
  c.history.insert(c.history.end(), lines.begin(), lines.end());
  ++c.starts;
  c.state.status = "running";
  c.state.running = true;
  c.state.paused = false;
}

Status FakeDockerApi::StopContainer(std::string_view id, int) {
  InFlight flight(*this, "stop");
  std::unique_lock lock(mu_);
  Container* c = Find(id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  const std::string component = c->component;
  if (!Rendezvous(lock, stop_together, stopped_together_, component)) {
    return Error(ErrorCode::kTimeout, component + " stopped alone", "POST /containers/stop");
  }
  c = Find(id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  if (Status f = Record("stop " + c->spec.name); !f) return f;
  if (c->state.running) {
    c->state.running = false;
    c->state.status = "exited";
    c->state.exit_code = 0;
  }
  cv_.notify_all();
  return Ok{};
}

Status FakeDockerApi::RestartContainer(std::string_view id, int timeout_s) {
  std::lock_guard lock(mu_);
  Container* c = Find(id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  if (Status f = Record("restart " + c->spec.name + " " + std::to_string(timeout_s)); !f) return f;
  StartLocked(*c);  // a new run: a follower of the old one sees `starts` change and ends
  cv_.notify_all();
  return Ok{};
}

Status FakeDockerApi::KillContainer(std::string_view id, std::string_view signal) {
  std::lock_guard lock(mu_);
  Container* c = Find(id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  if (Status f = Record("kill " + c->spec.name + " " + std::string(signal)); !f) return f;
  if (!c->state.running) {
    return Error(ErrorCode::kInvalidArgument, "Container " + std::string(id) + " is not running");
  }
  c->state.running = false;
  c->state.paused = false;
  c->state.status = "exited";
  c->state.exit_code = signal == "SIGTERM" ? 143 : 137;
  cv_.notify_all();
  return Ok{};
}

Status FakeDockerApi::PauseContainer(std::string_view id) {
  std::lock_guard lock(mu_);
  Container* c = Find(id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  if (Status f = Record("pause " + c->spec.name); !f) return f;
  if (!c->state.running) return Error(ErrorCode::kInvalidArgument, "container is not running");
  c->state.paused = true;
  c->state.status = "paused";
  return Ok{};
}

Status FakeDockerApi::UnpauseContainer(std::string_view id) {
  std::lock_guard lock(mu_);
  Container* c = Find(id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  if (Status f = Record("unpause " + c->spec.name); !f) return f;
  if (!c->state.paused) return Error(ErrorCode::kInvalidArgument, "container is not paused");
  c->state.paused = false;
  c->state.status = "running";
  return Ok{};
}
Result<std::int64_t> FakeDockerApi::WaitContainer(std::string_view, docker::WaitCondition,
                                                  docker::CancelToken*) {
  return NotModelled("WaitContainer");
}

Status FakeDockerApi::RemoveContainer(std::string_view id, bool force, bool) {
  InFlight flight(*this, "remove");
  std::lock_guard lock(mu_);
  Container* c = Find(id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  if (c->state.running && !force) return Error(ErrorCode::kInvalidArgument, "container is running");
  if (Status f = Record("remove " + c->spec.name); !f) return f;
  for (auto it = containers_.begin(); it != containers_.end(); ++it) {
    if (&it->second == c) {
      containers_.erase(it);
      break;
    }
  }
  cv_.notify_all();
  return Ok{};
}

Status FakeDockerApi::FollowLogs(std::string_view id, const docker::LogOptions&,
                                 const docker::LogLineFn& on_line, docker::CancelToken* cancel) {
  std::vector<std::string> lines;
  std::optional<std::int64_t> exit_code;
  bool broken = false;
  int starts = 0;
  {
    std::unique_lock lock(mu_);
    std::string component;
    if (Container* c = Find(id)) component = c->component;
    const std::set<std::string> awaited = scripts[component].log_after_created;
    auto all_created = [&] {
      return std::all_of(awaited.begin(), awaited.end(), [&](const std::string& a) {
        return std::any_of(containers_.begin(), containers_.end(),
                           [&](const auto& entry) { return entry.second.component == a; });
      });
    };
    if (!cv_.wait_for(lock, std::chrono::seconds(10), all_created)) {
      return Error(ErrorCode::kIo, "log_after_created: the awaited containers were never created");
    }
    const std::set<std::string> exits = scripts[component].log_after_exit_seen;
    auto all_exits_seen = [&] {
      return std::all_of(exits.begin(), exits.end(), [&](const std::string& a) {
        return std::any_of(containers_.begin(), containers_.end(), [&](const auto& entry) {
          return entry.second.component == a && entry.second.exit_inspected;
        });
      });
    };
    if (!cv_.wait_for(lock, std::chrono::seconds(10), all_exits_seen)) {
      return Error(ErrorCode::kIo, "log_after_exit_seen: the awaited containers' exits were never inspected");
    }
    Container* c = Find(id);
    if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
    ++c->follows;
    ContainerScript& s = scripts[c->component];
    lines = c->history;
    starts = c->starts;
    exit_code = s.exit_code;
    if (s.broken_streams > 0) {
      --s.broken_streams;
      broken = true;
      if (lines.size() > s.broken_stream_lines) lines.resize(s.broken_stream_lines);
    }
  }
  for (const std::string& l : lines) {
    if (cancel != nullptr && cancel->cancelled()) return Error(ErrorCode::kCancelled, "cancelled");
    on_line({docker::StreamKind::kStdout, l});
  }
  if (broken) return Error(ErrorCode::kIo, "connection reset by peer", "GET /containers/logs");
  std::unique_lock lock(mu_);
  if (exit_code) {
    Container* c = Find(id);
    if (c != nullptr && c->state.running) {
      c->state.running = false;
      c->state.status = "exited";
      c->state.exit_code = *exit_code;
    }
    return Ok{};
  }
  while (true) {
    Container* c = Find(id);
    if (c == nullptr || !c->state.running || c->starts != starts) return Ok{};
    if (cancel != nullptr && cancel->cancelled()) return Error(ErrorCode::kCancelled, "cancelled");
    cv_.wait_for(lock, std::chrono::milliseconds(10));
  }
}

Result<std::string> FakeDockerApi::CreateExec(std::string_view container_id, const docker::ExecSpec& spec) {
  std::lock_guard lock(mu_);
  Container* c = Find(container_id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "No such container: " + std::string(container_id));
  if (!c->state.running) {
    return Error(ErrorCode::kInvalidArgument, "Container " + std::string(container_id) + " is not running");
  }
  const std::string id = "e" + std::to_string(next_id_++);
  execs_[id] = Exec{c->spec.name, spec.cmd, std::nullopt};
  return id;
}

Status FakeDockerApi::StartExec(std::string_view exec_id, const docker::LogLineFn& on_line, docker::CancelToken*) {
  ExecAnswer answer;
  std::string call;
  {
    std::lock_guard lock(mu_);
    auto it = execs_.find(std::string(exec_id));
    if (it == execs_.end()) return Error(ErrorCode::kNotFound, "no such exec");
    std::string text;
    for (const auto& a : it->second.cmd) text += (text.empty() ? "" : " ") + a;
    call = "exec " + it->second.container + " " + text;
    if (Status f = Record(call); !f) return f;
    if (auto a = exec_answers.find(text); a != exec_answers.end()) answer = a->second;
    it->second.exit_code = answer.exit_code;
  }
  if (on_exec) on_exec(call);  // outside the lock: a test may look at the fake
  if (on_line) {
    for (const auto& l : answer.stdout_lines) on_line({docker::StreamKind::kStdout, l});
    for (const auto& l : answer.stderr_lines) on_line({docker::StreamKind::kStderr, l});
  }
  return Ok{};
}

Result<docker::ExecState> FakeDockerApi::InspectExec(std::string_view exec_id) {
  std::lock_guard lock(mu_);
  auto it = execs_.find(std::string(exec_id));
  if (it == execs_.end()) return Error(ErrorCode::kNotFound, "no such exec");
  docker::ExecState st;
  st.exit_code = it->second.exit_code;
  return st;
}

Status FakeDockerApi::PutArchive(std::string_view container_id, std::string_view dest_dir,
                                 std::string_view tar) {
  std::lock_guard lock(mu_);
  Container* c = Find(container_id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  // Docker's rule for a read-only root filesystem: archives go into a volume only.
  bool to_volume = false;
  for (const docker::Mount& m : c->spec.mounts) {
    const std::string prefix = m.target + "/";
    if (m.type == docker::Mount::Type::kVolume &&
        (dest_dir == m.target || std::string(dest_dir).rfind(prefix, 0) == 0)) {
      to_volume = true;
    }
  }
  if (c->spec.read_only_rootfs && !to_volume) {
    return Error(ErrorCode::kInvalidArgument, "container rootfs is marked read-only");
  }
  c->put_archive = std::string(tar);
  put_archives_[c->spec.name] = std::string(tar);
  put_archive_dirs_[c->spec.name] = std::string(dest_dir);
  return Ok{};
}

Result<std::string> FakeDockerApi::GetArchive(std::string_view container_id, std::string_view path) {
  std::lock_guard lock(mu_);
  Container* c = Find(container_id);
  if (c == nullptr) return Error(ErrorCode::kNotFound, "no such container");
  const auto& files = scripts[c->component].files;
  auto it = files.find(std::string(path));
  if (it == files.end()) return Error(ErrorCode::kNotFound, "Could not find the file " + std::string(path));
  docker::TarWriter tar;
  if (Status s = tar.AddFile(std::filesystem::path(std::string(path)).filename().string(), it->second); !s) {
    return s.error();
  }
  return tar.Finish();
}

Status FakeDockerApi::StreamEvents(const docker::EventFilter&, const docker::EventFn&,
                                   docker::CancelToken*) {
  return NotModelled("StreamEvents");
}

}  // namespace swarmbox::testing
