// Trial: the root of one trial's component tree, with what ends it (end conditions matched on
// logs, a timeout in simulated time with a wall-clock guard). Experiment groups trials.
//
//   Trial trial("sar-search", "r20261121-1305-7f3a");
//   ... Add<Network>(), Add<Plugin>() ...
//   trial.EndOn("event=mission_complete", Outcome::kSuccess);
//   trial.EndOn("event=collision", Outcome::kFailure, "collision");
//   trial.SetTimeout(TimeoutPolicy::Sim(Duration::Minutes(10), Duration::Minutes(15)));
//
//   Verdict v = trial.Start(engine);      // Build then Run, priority order
//   ... the runner watches logs; a match calls plugin.RaiseShutdown(...) ...
//   if (trial.restart_requested()) v = trial.Restart(engine);
//   v.KeepWorse(trial.Stop(engine));
//
// A Trial consumes the Shutdown and Restart events raised below it. The first Shutdown decides the
// trial's end verdict (later ones are consequences of the first and are ignored).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "swarmbox/dsl/component.hpp"
#include "swarmbox/dsl/duration.hpp"
#include "swarmbox/dsl/network.hpp"
#include "swarmbox/dsl/plugin.hpp"

namespace swarmbox::dsl {

// A regex searched in each log line of `component` (every component when empty). The pattern must
// end at a token boundary: "event=crash" does not match "event=crash_landing".
struct EndCondition {
  std::string pattern;
  Outcome outcome = Outcome::kSuccess;
  std::string reason;     // "" = the pattern
  std::string component;  // a Plugin id; "" = any
};

struct TimeoutPolicy {
  Duration sim;                        // simulated time; zero = none
  Duration wall_guard;                 // wall-clock time; zero = none
  Outcome outcome = Outcome::kTimeout;  // verdict when `sim` runs out (the guard gives kError)
  std::string clock_component;          // whose `t=` log fields are the simulated clock

  static TimeoutPolicy Sim(Duration sim, Duration wall_guard = {}, std::string clock_component = {}) {
    TimeoutPolicy p;
    p.sim = sim;
    p.wall_guard = wall_guard;
    p.clock_component = std::move(clock_component);
    return p;
  }
};

class Trial : public Component {
 public:
  explicit Trial(std::string name, std::string run_id = {});

  const std::string& name() const { return id(); }
  const std::string& run_id() const { return run_id_; }

  Trial& EndOn(std::string pattern, Outcome outcome, std::string reason = {},
               std::string component = {});
  Trial& SetTimeout(TimeoutPolicy policy);
  const std::vector<EndCondition>& end_conditions() const { return end_; }
  const TimeoutPolicy& timeout() const { return timeout_; }

  std::vector<Network*> Networks() { return Collect<Network>(); }
  std::vector<Plugin*> Plugins() { return Collect<Plugin>(); }
  Plugin* FindPlugin(std::string_view id);
  Network* FindNetwork(std::string_view id);

  // Build then Run down the tree; stops at the first problem (the caller then calls Stop()).
  Verdict Start(Engine& engine);
  // Stop down the tree (best-effort, reverse priority).
  Verdict Stop(Engine& engine);
  // Stop, then Start again; clears the request and counts it.
  Verdict Restart(Engine& engine);

  // The first Shutdown raised in this trial, if any.
  const std::optional<Verdict>& end_verdict() const { return end_verdict_; }
  bool restart_requested() const { return restart_requested_; }
  const std::string& restart_reason() const { return restart_reason_; }
  int restarts() const { return restarts_; }

 protected:
  bool OnShutdown(const Verdict& verdict) override;
  bool OnRestart(const std::string& reason, const std::string& source) override;

 private:
  std::string run_id_;
  std::vector<EndCondition> end_;
  TimeoutPolicy timeout_;
  std::optional<Verdict> end_verdict_;
  bool restart_requested_ = false;
  std::string restart_reason_;
  int restarts_ = 0;
};

// A list of trials, run in priority order (running experiments over hosts is a later issue; the
// tree node exists so trials have a parent that groups them).
class Experiment : public Component {
 public:
  explicit Experiment(std::string name) : Component(std::move(name)) {}
  std::vector<Trial*> Trials() { return Collect<Trial>(); }
};

}  // namespace swarmbox::dsl
