// Step: a Module that is not a container or a network, whose Run and Stop are work the runner
// binds after planning (e.g. the fault injector's set-up: detect the netem mechanism, apply the
// trial's network.mesh impairment before the agents start, and undo it on Stop). The planner places
// it in the tree by run priority; unbound callbacks do nothing.
//
//   auto& faults = trial.Add<Step>("faults", 3);          // after the sidecars, before the agents
//   ... runner: faults.Bind([&] { return injector.Setup(); }, [&] { return injector.Teardown(); });
//
// Build does nothing (a Step has nothing to create). Stop runs whenever the Step was built, also
// when its Run never came (an earlier start failed): the bound work must cope with that.
#pragma once

#include <functional>
#include <string>

#include "swarmbox/dsl/component.hpp"

namespace swarmbox::dsl {

class Step : public Module {
 public:
  using Work = std::function<Verdict()>;
  Step(std::string id, int run_priority) : Module(std::move(id), run_priority) {}

  void Bind(Work on_run, Work on_stop) {
    on_run_ = std::move(on_run);
    on_stop_ = std::move(on_stop);
  }
  bool bound() const { return static_cast<bool>(on_run_) || static_cast<bool>(on_stop_); }

 protected:
  Verdict DoBuild(Engine&) override { return Verdict::Success(); }
  Verdict DoRun(Engine&) override { return on_run_ ? on_run_() : Verdict::Success(); }
  Verdict DoStop(Engine&) override { return on_stop_ ? on_stop_() : Verdict::Success(); }

 private:
  Work on_run_;
  Work on_stop_;
};

}  // namespace swarmbox::dsl
