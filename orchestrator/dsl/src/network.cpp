#include "swarmbox/dsl/network.hpp"

#include <utility>

namespace swarmbox::dsl {

Network::Network(std::string id, NetworkSpec spec, int run_priority)
    : Module(std::move(id), run_priority), spec_(std::move(spec)) {}

Verdict Network::DoBuild(Engine& engine) { return engine.CreateNetwork(*this); }
// A network has nothing to start: it carries traffic once created.
Verdict Network::DoRun(Engine& /*engine*/) { return Verdict::Success(); }
Verdict Network::DoStop(Engine& engine) { return engine.RemoveNetwork(*this); }

}  // namespace swarmbox::dsl
