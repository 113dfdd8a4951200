// Network: a Docker network of one trial (a Module; run priority 0 by default, so networks exist
// before anything attaches to them and go last on Stop).
#pragma once

#include <map>
#include <string>
#include <utility>

#include "swarmbox/dsl/component.hpp"

namespace swarmbox::dsl {

struct NetworkSpec {
  std::string name;     // the Docker name, unique per host: "<trial>-<run>-sim"
  std::string subnet;   // CIDR, e.g. "10.77.3.0/24"
  std::string gateway;  // e.g. "10.77.3.1"; "" = Docker's choice
  bool internal = false;
  std::map<std::string, std::string> labels;

  // NetworkSpec::Subnet("demo-sim", "10.77.3.0/24")
  static NetworkSpec Subnet(std::string name, std::string subnet, std::string gateway = {}) {
    NetworkSpec n;
    n.name = std::move(name);
    n.subnet = std::move(subnet);
    n.gateway = std::move(gateway);
    return n;
  }
};

class Network : public Module {
 public:
  Network(std::string id, NetworkSpec spec, int run_priority = 0);

  const NetworkSpec& spec() const { return spec_; }
  // The runner may move a network to another subnet before Build (subnet conflict retry).
  NetworkSpec& mutable_spec() { return spec_; }

 protected:
  Verdict DoBuild(Engine& engine) override;
  Verdict DoRun(Engine& engine) override;
  Verdict DoStop(Engine& engine) override;

 private:
  NetworkSpec spec_;
};

}  // namespace swarmbox::dsl
