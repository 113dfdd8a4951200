#include "swarmbox/faults/fault_timeline.hpp"

#include <algorithm>

#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::faults {

bool LogLineMatches(std::string_view line, std::string_view pattern) {
  const LogfmtFields want = ParseLogfmt(pattern);
  if (want.empty()) return false;
  const LogfmtFields have = ParseLogfmt(line);
  for (const auto& [key, value] : want) {
    const auto got = FindField(have, key);
    if (!got || *got != value) return false;
  }
  return true;
}

FaultTimeline::FaultTimeline(std::vector<Fault> faults) : faults_(std::move(faults)), state_(faults_.size()) {}

void FaultTimeline::Apply(std::size_t i, double wall_s, std::vector<TimelineAction>* out) {
  State& s = state_[i];
  const Fault& f = faults_[i];
  s.applied = true;
  s.active = true;
  s.order = applied_count_++;
  if (f.duration_ms) {
    const double d_s = static_cast<double>(*f.duration_ms) / 1000.0;
    if (f.start.clock == FaultStart::Clock::kSim) {
      s.remove_sim_s = static_cast<double>(f.start.at_ms) / 1000.0 + d_s;
    } else if (f.start.clock == FaultStart::Clock::kWall) {
      s.remove_wall_s = static_cast<double>(f.start.at_ms) / 1000.0 + d_s;
    } else {
      s.remove_wall_s = wall_s + d_s;
    }
  }
  out->push_back({TimelineAction::Kind::kApply, i});
}

std::vector<TimelineAction> FaultTimeline::Advance(double sim_s, double wall_s) {
  std::vector<TimelineAction> out;
  for (std::size_t i = 0; i < faults_.size(); ++i) {
    State& s = state_[i];
    if (!s.active) continue;
    const bool due = (s.remove_sim_s && sim_s >= *s.remove_sim_s) || (s.remove_wall_s && wall_s >= *s.remove_wall_s);
    if (due) {
      s.active = false;
      out.push_back({TimelineAction::Kind::kRemove, i});
    }
  }
  for (std::size_t i = 0; i < faults_.size(); ++i) {
    if (state_[i].applied) continue;
    const FaultStart& start = faults_[i].start;
    const double at_s = static_cast<double>(start.at_ms) / 1000.0;
    if ((start.clock == FaultStart::Clock::kSim && sim_s >= at_s) ||
        (start.clock == FaultStart::Clock::kWall && wall_s >= at_s)) {
      Apply(i, wall_s, &out);
      // A fault whose whole window has passed (a coarse timer) is removed in the same call.
      State& s = state_[i];
      if ((s.remove_sim_s && sim_s >= *s.remove_sim_s) || (s.remove_wall_s && wall_s >= *s.remove_wall_s)) {
        s.active = false;
        out.push_back({TimelineAction::Kind::kRemove, i});
      }
    }
  }
  return out;
}

std::vector<TimelineAction> FaultTimeline::OnLogLine(std::string_view line, double wall_s) {
  std::vector<TimelineAction> out;
  for (std::size_t i = 0; i < faults_.size(); ++i) {
    if (state_[i].applied || faults_[i].start.clock != FaultStart::Clock::kEvent) continue;
    if (LogLineMatches(line, faults_[i].start.event_pattern)) Apply(i, wall_s, &out);
  }
  return out;
}

std::vector<TimelineAction> FaultTimeline::RemoveAll() {
  std::vector<std::size_t> active;
  for (std::size_t i = 0; i < faults_.size(); ++i) {
    if (state_[i].active) active.push_back(i);
  }
  std::sort(active.begin(), active.end(),
            [&](std::size_t a, std::size_t b) { return state_[a].order > state_[b].order; });
  std::vector<TimelineAction> out;
  for (std::size_t i : active) {
    state_[i].active = false;
    out.push_back({TimelineAction::Kind::kRemove, i});
  }
  return out;
}

}  // namespace swarmbox::faults
