// The host pool of an experiment, made ready before the first trial: every host connected and
// given its images (the trial images, and the fault sidecar image when a trial needs it), each
// host on its own thread (a remote build is slow). A host that cannot be connected or whose
// images fail is left out, with the reason; the others make the pool.
//
//   HostPoolSetup setup;
//   setup.connect = ConnectThroughHosts("/tmp/swarmbox-" + run_id);   // hosts::ConnectHost
//   setup.trial_images = [&](docker::DockerApi& api, const ImageProgressFn& p) {
//     return cli::EnsureTrialImages(api, programs, p);
//   };
//   setup.on_left_out = [](const std::string& host, const std::string& why) { ... };
//   HostPool pool = PrepareHostPool(plan, *ParseHostSpecs({"local?slots=2"}), setup);
//   if (pool.hosts().empty()) ...;                 // no host is usable
//   RunExperiment(plan, pool.hosts(), options);
//   pool.Disconnect();                             // closes the ssh tunnels
//
// The connections are behind PoolEngine, so a test prepares a pool of fake engines
// (tests/orchestrator/experiment/host_pool_test.cpp).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/experiment/experiment_runner.hpp"
#include "swarmbox/hosts/host_spec.hpp"
#include "swarmbox/runner/plan.hpp"

namespace swarmbox::experiment {

// One connected engine of the pool: it owns the connection (the ssh tunnel, the client), and its
// api() is valid while it lives.
class PoolEngine {
 public:
  virtual ~PoolEngine() = default;
  virtual docker::DockerApi& api() = 0;
  // Whether the engine answers now, with a host-level explanation when not (PoolHost::check).
  virtual Status Check() = 0;
};

using ImageProgressFn = std::function<void(std::string_view line)>;

struct HostPoolSetup {
  // Connects one host (ConnectThroughHosts: hosts::ConnectHost). Required.
  std::function<Result<std::unique_ptr<PoolEngine>>(const hosts::HostSpec&)> connect;
  // The physics server's and the agent's images on a connected engine (`swarmbox experiment`:
  // cli::EnsureTrialImages from the host-built programs). Required.
  std::function<Result<runner::Images>(docker::DockerApi&, const ImageProgressFn&)> trial_images;
  // The fault sidecar image on a connected engine, "" when none is needed; empty function =
  // EnsurePlanFaultsImage of the plan.
  std::function<Result<std::string>(docker::DockerApi&, const ImageProgressFn&)> faults_image;
  // A host left out of the pool and why ("<error>" when it did not connect, "images: <error>"
  // when its images failed). May be empty.
  std::function<void(const std::string& host, const std::string& why)> on_left_out;
  // The image builds' progress lines, by host name; empty = quiet.
  std::function<void(const std::string& host, std::string_view line)> on_progress;
  // on_left_out and on_progress are called from the hosts' threads, one call at a time.
};

// The pool: the usable hosts in the order of the specs, and the connections behind them.
class HostPool {
 public:
  HostPool() = default;
  HostPool(HostPool&&) = default;
  HostPool& operator=(HostPool&&) = default;
  HostPool(const HostPool&) = delete;
  HostPool& operator=(const HostPool&) = delete;

  // For RunExperiment: each PoolHost's api and check point into this pool's engines.
  const std::vector<PoolHost>& hosts() const { return hosts_; }
  // Closes every connection (an ssh host's tunnel); hosts() is empty afterwards.
  void Disconnect();

 private:
  friend HostPool PrepareHostPool(const ExperimentPlan&, const std::vector<hosts::HostSpec>&,
                                  const HostPoolSetup&);
  std::vector<std::unique_ptr<PoolEngine>> engines_;  // declared first: outlives hosts_
  std::vector<PoolHost> hosts_;
};

// Connects every host and makes its images, all hosts at once; returns when every host is done.
HostPool PrepareHostPool(const ExperimentPlan& plan, const std::vector<hosts::HostSpec>& specs,
                         const HostPoolSetup& setup);

// HostPoolSetup::connect through hosts::ConnectHost; `workdir` holds the forwarded sockets and the
// ssh logs (unix socket paths are limited to 108 bytes: keep it short).
std::function<Result<std::unique_ptr<PoolEngine>>(const hosts::HostSpec&)> ConnectThroughHosts(
    std::string workdir);

}  // namespace swarmbox::experiment
