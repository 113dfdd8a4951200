#include "swarm_run.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "program_images.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/dsl/trial_loader.hpp"
#include "swarmbox/runner/clock.hpp"
#include "swarmbox/runner/naming.hpp"

namespace swarmbox::swarm {

namespace {

namespace fs = std::filesystem;

Result<runner::Images> Images(docker::DockerApi& api, std::ostream* progress) {
  static std::mutex mu;
  static std::optional<runner::Images> cached;
  std::lock_guard<std::mutex> lk(mu);
  if (cached) return *cached;
  auto images = cli::EnsureTrialImages(
      api, cli::ProgramPaths{.physics_bin = SWARMBOX_PHYSICS_BIN, .agent_bin = SWARMBOX_AGENT_BIN},
      [progress](std::string_view line) {
        if (progress != nullptr) *progress << "  " << line << std::endl;
      });
  if (!images) return images.error();
  cached = *images;
  return *cached;
}

std::optional<double> ReadNumber(const fs::path& file) {
  std::ifstream in(file);
  double v = 0;
  if (!(in >> v)) return std::nullopt;
  return v;
}

// A container's counters from its cgroup: v1 (cgroupfs driver: /sys/fs/cgroup/<ctl>/docker/<id>)
// or v2 (systemd driver: /sys/fs/cgroup/system.slice/docker-<id>.scope). nullopt when neither is
// readable (the container is gone, or the cgroup tree is not mounted here).
std::optional<CgroupSample> ReadCgroup(const std::string& id) {
  const fs::path root = "/sys/fs/cgroup";
  if (auto cpu_ns = ReadNumber(root / "cpuacct" / "docker" / id / "cpuacct.usage")) {
    CgroupSample s;
    s.cpu_s = *cpu_ns / 1e9;
    s.mem_mib = ReadNumber(root / "memory" / "docker" / id / "memory.usage_in_bytes").value_or(0) / 1048576.0;
    s.mem_peak_mib = ReadNumber(root / "memory" / "docker" / id / "memory.max_usage_in_bytes").value_or(0) / 1048576.0;
    return s;
  }
  const fs::path scope = root / "system.slice" / ("docker-" + id + ".scope");
  std::ifstream stat(scope / "cpu.stat");
  std::string key;
  double value = 0;
  while (stat >> key >> value) {
    if (key != "usage_usec") continue;
    CgroupSample s;
    s.cpu_s = value / 1e6;
    s.mem_mib = ReadNumber(scope / "memory.current").value_or(0) / 1048576.0;
    s.mem_peak_mib = ReadNumber(scope / "memory.peak").value_or(s.mem_mib * 1048576.0) / 1048576.0;
    return s;
  }
  return std::nullopt;
}

// Samples the run's containers every `every` on its own engine connection until stopped.
class CgroupSampler {
 public:
  CgroupSampler(std::string run_id, std::chrono::milliseconds every) : run_id_(std::move(run_id)), every_(every) {
    thread_ = std::thread([this] { Loop(); });
  }
  ~CgroupSampler() { Stop(); }
  void Stop() {
    {
      std::lock_guard<std::mutex> lk(mu_);
      stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  const CgroupSamples& samples() const { return samples_; }
  int containers_read() const { return static_cast<int>(read_.size()); }

 private:
  void Loop() {
    auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
    if (!client) return;
    docker::LabelSelector run;
    run.equals[std::string(docker::kLabelRun)] = run_id_;
    std::unique_lock<std::mutex> lk(mu_);
    while (!stop_) {
      lk.unlock();
      CgroupSnapshot sample;
      sample.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
      if (auto list = (*client)->ListContainers(run, /*all=*/false)) {
        for (const docker::ContainerSummary& c : *list) {
          auto name = c.labels.find(std::string(docker::kLabelComponent));
          if (name == c.labels.end()) continue;
          if (auto s = ReadCgroup(c.id)) {
            sample.containers[name->second] = *s;
            read_.insert(name->second);
          }
        }
      }
      lk.lock();
      if (!sample.containers.empty()) samples_.push_back(std::move(sample));
      cv_.wait_for(lk, every_, [this] { return stop_; });
    }
  }

  std::string run_id_;
  std::chrono::milliseconds every_;
  // The samples' wall_s origin: made just before the runner's own start (events.jsonl's wall_s 0,
  // which comes after the trial folder is prepared: tens of ms later, well within `every_`).
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
  std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  CgroupSamples samples_;
  std::set<std::string> read_;
  std::thread thread_;
};

}  // namespace

double SearchSideM(int scouts) { return std::max(150.0, std::round(std::sqrt(static_cast<double>(scouts)) * 60.0)); }

Result<dsl::TrialSpec> LoadSwarmTrial(int scouts, double sim_s, const std::vector<std::string>& sets) {
  dsl::LoadOptions load;
  const std::string side = std::to_string(static_cast<int>(SearchSideM(scouts)));
  load.overrides = {"drones.scout.count=" + std::to_string(scouts), "world_size_m=[" + side + "," + side + "]"};
  if (sim_s > 0) load.overrides.push_back("timeout.sim=" + std::to_string(static_cast<int>(std::ceil(sim_s))) + "s");
  load.overrides.insert(load.overrides.end(), sets.begin(), sets.end());
  return dsl::LoadTrial(std::string(SWARMBOX_SOURCE_DIR) + "/trials/swarm_100.yaml", load);
}

Result<std::unique_ptr<docker::DockerApi>> ConnectDocker() {
  auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
  if (!client) return client.error().Context("the swarm trials need a Docker engine");
  return std::unique_ptr<docker::DockerApi>(std::move(*client));
}

Result<SwarmRun> RunSwarmTrial(docker::DockerApi& api, const dsl::TrialSpec& spec, const SwarmRunConfig& config) {
  auto images = Images(api, config.progress);
  if (!images) return images.error().Context("building the trial images");
  runner::RunOptions options;
  options.out_dir = config.out_dir;
  options.run_id = runner::NewRunId();
  options.images = *images;
  options.progress = config.progress;
  runner::SteadyClock clock;
  CgroupSampler sampler(options.run_id, std::chrono::milliseconds(1000));
  auto outcome = runner::RunTrialSpec(spec, api, clock, options);
  sampler.Stop();
  docker::LabelSelector run;
  run.equals[std::string(docker::kLabelRun)] = options.run_id;
  auto swept = docker::RemoveLabelled(api, run, /*include_images=*/false);
  if (!outcome) return outcome.error();
  if (!swept) return swept.error().Context("removing what run " + options.run_id + " left");
  SwarmRun out;
  out.outcome = std::move(*outcome);
  out.cgroups_read = sampler.containers_read();
  std::ifstream events(fs::path(out.outcome.trial_dir) / "events.jsonl");
  for (std::string line; std::getline(events, line);) out.events.push_back(line);
  std::ifstream result(fs::path(out.outcome.trial_dir) / "result.json");
  std::ostringstream text;
  text << result.rdbuf();
  std::vector<std::string> drones;
  for (const dsl::DroneSpec& d : spec.drones) drones.push_back(d.name);
  out.figures = ComputeSwarmFigures(ParseResultJson(text.str()), out.events, sampler.samples(), drones);
  return out;
}

}  // namespace swarmbox::swarm
