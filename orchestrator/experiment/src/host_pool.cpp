#include "swarmbox/experiment/host_pool.hpp"

#include <mutex>
#include <optional>
#include <thread>

#include "swarmbox/hosts/host.hpp"

namespace swarmbox::experiment {

namespace {

// A host of hosts::ConnectHost (the local engine, or a remote one through its ssh tunnel).
class ConnectedHost final : public PoolEngine {
 public:
  explicit ConnectedHost(std::unique_ptr<hosts::Host> host) : host_(std::move(host)) {}
  docker::DockerApi& api() override { return host_->api(); }
  Status Check() override { return host_->Check(); }

 private:
  std::unique_ptr<hosts::Host> host_;
};

// One host's preparation, on its own thread: what it leaves in its slot is a ready engine with
// its images, or nothing (and a call of on_left_out).
class HostPreparation {
 public:
  HostPreparation(const ExperimentPlan& plan, const HostPoolSetup& setup, std::mutex& report_mu)
      : plan_(plan), setup_(setup), report_mu_(report_mu) {}

  struct Ready {
    std::unique_ptr<PoolEngine> engine;
    runner::Images images;
    std::string faults_image;
  };

  std::optional<Ready> Prepare(const hosts::HostSpec& spec) {
    const std::string name = spec.name();
    auto engine = setup_.connect(spec);
    if (!engine) return LeftOut(name, engine.error().ToString());
    const ImageProgressFn progress = [this, &name](std::string_view line) { Progress(name, line); };
    auto images = setup_.trial_images((*engine)->api(), progress);
    if (!images) return LeftOut(name, "images: " + images.error().ToString());
    auto faults = setup_.faults_image ? setup_.faults_image((*engine)->api(), progress)
                                      : EnsurePlanFaultsImage(plan_, (*engine)->api(), progress);
    if (!faults) return LeftOut(name, "images: " + faults.error().ToString());
    return Ready{std::move(*engine), std::move(*images), std::move(*faults)};
  }

 private:
  std::nullopt_t LeftOut(const std::string& host, const std::string& why) {
    if (setup_.on_left_out) {
      std::lock_guard lock(report_mu_);
      setup_.on_left_out(host, why);
    }
    return std::nullopt;
  }

  void Progress(const std::string& host, std::string_view line) {
    if (!setup_.on_progress) return;
    std::lock_guard lock(report_mu_);
    setup_.on_progress(host, line);
  }

  const ExperimentPlan& plan_;
  const HostPoolSetup& setup_;
  std::mutex& report_mu_;
};

}  // namespace

void HostPool::Disconnect() {
  hosts_.clear();
  engines_.clear();
}

HostPool PrepareHostPool(const ExperimentPlan& plan, const std::vector<hosts::HostSpec>& specs,
                         const HostPoolSetup& setup) {
  std::mutex report_mu;
  HostPreparation preparation(plan, setup, report_mu);
  std::vector<std::optional<HostPreparation::Ready>> ready(specs.size());
  {
    std::vector<std::jthread> threads;
    for (std::size_t i = 0; i < specs.size(); ++i) {
      threads.emplace_back([&, i] { ready[i] = preparation.Prepare(specs[i]); });
    }
  }  // joins every thread
  HostPool pool;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    if (!ready[i]) continue;
    PoolEngine* engine = ready[i]->engine.get();
    pool.engines_.push_back(std::move(ready[i]->engine));
    pool.hosts_.push_back({specs[i].name(), specs[i].slots, &engine->api(), [engine] { return engine->Check(); },
                           std::move(ready[i]->images), std::move(ready[i]->faults_image)});
  }
  return pool;
}

std::function<Result<std::unique_ptr<PoolEngine>>(const hosts::HostSpec&)> ConnectThroughHosts(
    std::string workdir) {
  return [workdir = std::move(workdir)](const hosts::HostSpec& spec) -> Result<std::unique_ptr<PoolEngine>> {
    auto host = hosts::ConnectHost(spec, workdir);
    if (!host) return host.error();
    return std::unique_ptr<PoolEngine>(std::make_unique<ConnectedHost>(std::move(*host)));
  };
}

}  // namespace swarmbox::experiment
