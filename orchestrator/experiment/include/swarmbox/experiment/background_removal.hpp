// Removing a finished trial's containers and networks in the background, so an experiment slot
// launches its next trial once the last one's result.json, logs and artifacts are written rather
// than once Docker has also removed its containers and networks (~0.5 s of a SAR trial's ~1.2 s
// teardown on this machine: the container deletions and the two network removals).
//
//   BackgroundRemover remover(host_api);           // one per host, one thread
//   {
//     DeferredRemovalApi api(host_api, remover);   // one per trial attempt
//     runner::RunTrialSpec(spec, api, clock, options);  // removals are queued, not waited for
//   }
//   remover.Drain();                                // before the run's leftover sweep and exit
//   for (auto& p : remover.TakeProblems()) ...
//
// DeferredRemovalApi forwards every call to the host's API except RemoveContainer and
// RemoveNetwork, which it queues on the remover and answers Ok at once. Before it creates a
// container or a network it waits for its own queued removals (a restart or another subnet pair
// creates the same names again). The remover works through its queue in order, so a trial's
// containers (queued by the runner's stops) are gone before its networks (queued after them) are
// removed. Network removal Docker 20.10 refuses for a stale endpoint ("has active endpoints",
// moby#43286) is retried for ~3 s, as the runner does.
//
// Guarantees: everything stays labelled (swarmbox.run, swarmbox.trial), so what a crash leaves
// queued is found by `swarmbox gc --run` and by `swarmbox experiment --resume`; the destructor
// drains the queue; a failed removal is a problem for the experiment's summary (not the trial's
// result.json, which is written by then), and the run's leftover sweep removes it.
// Thread-safety: both classes may be used from any thread.
#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "swarmbox/docker/docker_api.hpp"

namespace swarmbox::experiment {

class BackgroundRemover {
 public:
  // `host` names the host in problems. The thread starts with the first removal.
  BackgroundRemover(docker::DockerApi& api, std::string host);
  ~BackgroundRemover();  // drains, then joins
  BackgroundRemover(const BackgroundRemover&) = delete;
  BackgroundRemover& operator=(const BackgroundRemover&) = delete;

  // What one DeferredRemovalApi has queued and not yet seen done.
  struct Batch {
    int pending = 0;  // guarded by BackgroundRemover::mu_
  };

  void RemoveContainer(std::string id, bool remove_volumes, const std::shared_ptr<Batch>& batch);
  void RemoveNetwork(std::string id, const std::shared_ptr<Batch>& batch);
  // Waits until every removal of `batch` is done.
  void Flush(const std::shared_ptr<Batch>& batch);
  // Waits until the queue is empty and nothing is being removed.
  void Drain();
  // Removals that failed ("<host>: removing container <id>: <error>"), since the last call.
  std::vector<std::string> TakeProblems();

 private:
  struct Item {
    enum class Kind { kContainer, kNetwork } kind = Kind::kContainer;
    std::string id;
    bool remove_volumes = true;
    std::shared_ptr<Batch> batch;
  };
  void Enqueue(Item item);
  void Work();
  void Remove(const Item& item);

  docker::DockerApi& api_;
  std::string host_;
  std::mutex mu_;
  std::condition_variable cv_;  // work queued, work done, stopping
  std::deque<Item> queue_;      // guarded by mu_
  bool busy_ = false;           // guarded by mu_: an item is being removed
  bool stopping_ = false;       // guarded by mu_
  std::vector<std::string> problems_;  // guarded by mu_
  std::thread thread_;                 // started by the first Enqueue (under mu_)
};

class DeferredRemovalApi final : public docker::DockerApi {
 public:
  DeferredRemovalApi(docker::DockerApi& inner, BackgroundRemover& remover);
  ~DeferredRemovalApi() override = default;

  Result<std::string> Ping() override { return inner_.Ping(); }
  Result<docker::EngineVersion> Version() override { return inner_.Version(); }
  std::string api_version() const override { return inner_.api_version(); }
  Result<docker::BuildResult> BuildImage(const docker::BuildRequest& request,
                                         const docker::BuildProgressFn& progress,
                                         docker::CancelToken* cancel) override {
    return inner_.BuildImage(request, progress, cancel);
  }
  Result<docker::ImageInfo> InspectImage(std::string_view reference) override {
    return inner_.InspectImage(reference);
  }
  Result<std::vector<docker::ImageInfo>> ListImages(const docker::LabelSelector& selector) override {
    return inner_.ListImages(selector);
  }
  Status RemoveImage(std::string_view reference, bool force) override {
    return inner_.RemoveImage(reference, force);
  }
  Result<std::string> CreateNetwork(const docker::NetworkSpec& spec) override;
  Result<docker::NetworkInfo> InspectNetwork(std::string_view id) override {
    return inner_.InspectNetwork(id);
  }
  Result<std::vector<docker::NetworkInfo>> ListNetworks(const docker::LabelSelector& selector) override {
    return inner_.ListNetworks(selector);
  }
  Status ConnectNetwork(const docker::EndpointSpec& endpoint, std::string_view container_id) override {
    return inner_.ConnectNetwork(endpoint, container_id);
  }
  Status DisconnectNetwork(std::string_view network_id, std::string_view container_id,
                           bool force) override {
    return inner_.DisconnectNetwork(network_id, container_id, force);
  }
  Status RemoveNetwork(std::string_view id) override;  // queued
  Result<std::string> CreateContainer(const docker::ContainerSpec& spec) override;
  Result<docker::ContainerInfo> InspectContainer(std::string_view id) override {
    return inner_.InspectContainer(id);
  }
  Result<std::vector<docker::ContainerSummary>> ListContainers(const docker::LabelSelector& selector,
                                                               bool all) override {
    return inner_.ListContainers(selector, all);
  }
  Status StartContainer(std::string_view id) override { return inner_.StartContainer(id); }
  Status StopContainer(std::string_view id, int timeout_s) override {
    return inner_.StopContainer(id, timeout_s);
  }
  Status RestartContainer(std::string_view id, int timeout_s) override {
    return inner_.RestartContainer(id, timeout_s);
  }
  Status KillContainer(std::string_view id, std::string_view signal) override {
    return inner_.KillContainer(id, signal);
  }
  Status PauseContainer(std::string_view id) override { return inner_.PauseContainer(id); }
  Status UnpauseContainer(std::string_view id) override { return inner_.UnpauseContainer(id); }
  Result<std::int64_t> WaitContainer(std::string_view id, docker::WaitCondition condition,
                                     docker::CancelToken* cancel) override {
    return inner_.WaitContainer(id, condition, cancel);
  }
  // Queued (always forced, as the runner removes).
  Status RemoveContainer(std::string_view id, bool force, bool remove_volumes) override;
  Status FollowLogs(std::string_view id, const docker::LogOptions& options,
                    const docker::LogLineFn& on_line, docker::CancelToken* cancel) override {
    return inner_.FollowLogs(id, options, on_line, cancel);
  }
  Result<std::string> CreateExec(std::string_view container_id, const docker::ExecSpec& spec) override {
    return inner_.CreateExec(container_id, spec);
  }
  Status StartExec(std::string_view exec_id, const docker::LogLineFn& on_line,
                   docker::CancelToken* cancel) override {
    return inner_.StartExec(exec_id, on_line, cancel);
  }
  Result<docker::ExecState> InspectExec(std::string_view exec_id) override {
    return inner_.InspectExec(exec_id);
  }
  Status PutArchive(std::string_view container_id, std::string_view dest_dir,
                    std::string_view tar) override {
    return inner_.PutArchive(container_id, dest_dir, tar);
  }
  Result<std::string> GetArchive(std::string_view container_id, std::string_view path) override {
    return inner_.GetArchive(container_id, path);
  }
  Status StreamEvents(const docker::EventFilter& filter, const docker::EventFn& on_event,
                      docker::CancelToken* cancel) override {
    return inner_.StreamEvents(filter, on_event, cancel);
  }

 private:
  docker::DockerApi& inner_;
  BackgroundRemover& remover_;
  std::shared_ptr<BackgroundRemover::Batch> batch_ = std::make_shared<BackgroundRemover::Batch>();
};

}  // namespace swarmbox::experiment
