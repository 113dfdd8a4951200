// Monitor: the pure core of watching a running trial. Fed log lines, container exits and the wall
// clock; answers when the trial ends and why. No threads, no Docker, no clock of its own.
//
//   Monitor m = *Monitor::Create(trial);
//   m.Started("physics");
//   if (auto v = m.OnLine("physics", "t=601.000 node=physics event=tick")) ...   // sim timeout
//   if (auto v = m.OnTick(wall_s)) ...                                          // wall-clock guard
//
// Rules, first to fire wins (later inputs return nullopt):
//   - an end condition matches a line                      -> its outcome and reason
//   - simulated time (max `t=` of the clock component's log) reaches timeout.sim -> timeout.outcome,
//     after a drain window of kTimeoutDrainS wall seconds: the containers' logs are separate
//     streams, so an agent's ending line stamped before the timeout can reach us after the clock
//     component's line that crossed it (seen at rtf 0, where simulated time races ahead). Lines
//     that match an end condition during the window still win; a container exiting during it
//     (the physics server stops at the timeout) confirms the timeout.
//   - a started container exits                            -> failure "<c> exited with code N"
//     unless its ExitRule allows it: a brain may go at any time (its drone's offboard failsafe is
//     the answer, recorded by the agent), a user component may finish with code 0 (a job done)
//   - wall time reaches timeout.wall_guard                  -> error "wall-clock guard: ..."
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include "swarmbox/dsl/trial.hpp"
#include "swarmbox/runner/end_matcher.hpp"
#include "swarmbox/runner/trial_progress.hpp"

namespace swarmbox::runner {

class Monitor {
 public:
  static constexpr double kTimeoutDrainS = 1.0;

  static Result<Monitor> Create(dsl::Trial& trial);

  // How a container leaving is judged (default kCrashEnds).
  enum class ExitRule { kCrashEnds, kAnyExitAllowed, kCleanExitAllowed };
  void SetExitRule(std::string_view component, ExitRule rule);

  void Started(std::string_view component);
  std::optional<dsl::Verdict> OnLine(std::string_view component, std::string_view line);
  std::optional<dsl::Verdict> OnExit(std::string_view component, std::int64_t exit_code,
                                     bool oom_killed);
  std::optional<dsl::Verdict> OnTick(double wall_s);

  // Simulated time [s]: the clock component's, or when it is behind (the physics server logs
  // only on events) the latest `t=` of any component. Timeouts use the clock component's only.
  double sim_s() const { return sim_s_ > any_sim_s_ ? sim_s_ : any_sim_s_; }
  double wall_s() const { return wall_s_; }
  bool ended() const { return ended_.has_value(); }
  const std::optional<dsl::Verdict>& verdict() const { return ended_; }
  // The log line that ended the trial, if a line did.
  const std::string& ending_line() const { return ending_line_; }
  const std::set<std::string>& live() const { return live_; }

  // What the log lines said so far (trial_progress.hpp).
  const TrialProgress& progress() const { return progress_; }
  // One status line for the terminal (RenderProgress):
  // "sim 41.2/600.0s  rtf 0.98  wall 43.0s  stage SEARCH  leader scout_2  victims sighted 3
  //  confirmed 2 rescued 1  live 5/5"
  std::string ProgressLine() const;

 private:
  Monitor(EndMatcher matcher, dsl::TimeoutPolicy timeout, std::size_t components);
  std::optional<dsl::Verdict> End(dsl::Verdict v);

  EndMatcher matcher_;
  dsl::TimeoutPolicy timeout_;
  std::size_t components_;
  double sim_s_ = 0;      // the clock component's
  double any_sim_s_ = 0;  // any component's
  double wall_s_ = 0;
  std::set<std::string> live_;
  std::map<std::string, ExitRule, std::less<>> exit_rules_;
  TrialProgress progress_;
  std::optional<dsl::Verdict> ended_;
  std::optional<dsl::Verdict> timeout_pending_;  // simulated time ran out; draining the streams
  double timeout_seen_wall_s_ = 0;
  std::string ending_line_;
};

}  // namespace swarmbox::runner
