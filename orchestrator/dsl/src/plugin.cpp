#include "swarmbox/dsl/plugin.hpp"

#include <utility>

#include "swarmbox/dsl/network.hpp"

namespace swarmbox::dsl {

Plugin::Plugin(std::string id, ContainerSpec spec, int run_priority)
    : Module(std::move(id), run_priority), spec_(std::move(spec)) {}

Plugin& Plugin::On(const Network& network, std::string ipv4, std::vector<std::string> aliases) {
  spec_.networks.push_back({network.id(), std::move(ipv4), std::move(aliases)});
  return *this;
}

Plugin& Plugin::ReadyOn(std::string pattern, Duration timeout) {
  spec_.ready_pattern = std::move(pattern);
  spec_.ready_timeout = timeout;
  return *this;
}

Plugin& Plugin::Collect(std::string path_in_container) {
  spec_.artifacts.push_back(std::move(path_in_container));
  return *this;
}

Plugin& Plugin::Env(std::string key, std::string value) {
  spec_.env[std::move(key)] = std::move(value);
  return *this;
}

Plugin& Plugin::Priority(int run_priority) {
  set_run_priority(run_priority);
  return *this;
}

Verdict Plugin::DoBuild(Engine& engine) { return engine.CreateContainer(*this); }
Verdict Plugin::DoRun(Engine& engine) { return engine.StartContainer(*this); }
Verdict Plugin::DoStop(Engine& engine) { return engine.StopContainer(*this); }

}  // namespace swarmbox::dsl
