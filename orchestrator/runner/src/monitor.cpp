#include "swarmbox/runner/monitor.hpp"

#include <cstdio>


namespace swarmbox::runner {

namespace {

std::string Seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", s);
  return buf;
}
}  // namespace

Result<Monitor> Monitor::Create(dsl::Trial& trial) {
  auto matcher = EndMatcher::Compile(trial.end_conditions());
  if (!matcher) return matcher.error();
  return Monitor(std::move(*matcher), trial.timeout(), trial.Plugins().size());
}

Monitor::Monitor(EndMatcher matcher, dsl::TimeoutPolicy timeout, std::size_t components)
    : matcher_(std::move(matcher)), timeout_(std::move(timeout)), components_(components) {}

void Monitor::Started(std::string_view component) { live_.insert(std::string(component)); }

std::optional<dsl::Verdict> Monitor::End(dsl::Verdict v) {
  if (ended_) return std::nullopt;
  ended_ = v;
  return v;
}

std::optional<dsl::Verdict> Monitor::OnLine(std::string_view component, std::string_view line) {
  if (ended_) return std::nullopt;
  progress_.OnLine(component, line);
  if (auto t = SimTimeOf(line)) {
    if (*t > any_sim_s_) any_sim_s_ = *t;
    if ((timeout_.clock_component.empty() || timeout_.clock_component == component) && *t > sim_s_) {
      sim_s_ = *t;
    }
  }
  if (auto v = matcher_.Match(component, line)) {
    ending_line_ = std::string(line);
    return End(std::move(*v));
  }
  if (!timeout_pending_ && !timeout_.sim.zero() && sim_s_ >= timeout_.sim.seconds()) {
    timeout_pending_ = dsl::Verdict::Of(
        timeout_.outcome, "simulated time ran out (" + timeout_.sim.ToString() + ")", "timeout");
    timeout_seen_wall_s_ = wall_s_;
  }
  return std::nullopt;
}

void Monitor::SetExitRule(std::string_view component, ExitRule rule) {
  exit_rules_[std::string(component)] = rule;
}

std::optional<dsl::Verdict> Monitor::OnExit(std::string_view component, std::int64_t exit_code,
                                            bool oom_killed) {
  live_.erase(std::string(component));
  if (ended_) return std::nullopt;
  if (timeout_pending_) return End(*timeout_pending_);
  if (auto rule = exit_rules_.find(component); rule != exit_rules_.end() && !oom_killed) {
    if (rule->second == ExitRule::kAnyExitAllowed) return std::nullopt;
    if (rule->second == ExitRule::kCleanExitAllowed && exit_code == 0) return std::nullopt;
  }
  std::string why = oom_killed ? std::string(component) + " was killed for lack of memory"
                               : std::string(component) + " exited with code " +
                                     std::to_string(exit_code) + " before the trial ended";
  return End(dsl::Verdict::Failure(std::move(why), std::string(component)));
}

std::optional<dsl::Verdict> Monitor::OnTick(double wall_s) {
  if (wall_s > wall_s_) wall_s_ = wall_s;
  if (ended_) return std::nullopt;
  if (timeout_pending_ && wall_s_ - timeout_seen_wall_s_ >= kTimeoutDrainS) {
    return End(*timeout_pending_);
  }
  if (!timeout_.wall_guard.zero() && wall_s_ >= timeout_.wall_guard.seconds()) {
    return End(dsl::Verdict::Err("wall-clock guard: " + timeout_.wall_guard.ToString() +
                                     " passed with simulated time at " + Seconds(sim_s()) + "s of " +
                                     timeout_.sim.ToString(),
                                 "wall-clock guard"));
  }
  return std::nullopt;
}

std::string Monitor::ProgressLine() const {
  return RenderProgress(progress_, {timeout_.sim.seconds(), wall_s_, live_.size(), components_});
}

}  // namespace swarmbox::runner
