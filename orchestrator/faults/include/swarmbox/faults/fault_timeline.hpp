// FaultTimeline: when each fault of a schedule is applied and removed. Pure: the runner feeds it
// the clocks and the log lines it sees, and carries out what it returns.
//
//   FaultTimeline timeline(faults);
//   // on every log line (any container):
//   for (auto& a : timeline.OnLogLine(line, wall_s)) Carry(a);
//   // on a timer (e.g. every 50 ms) with the latest simulated time (`t=` of the physics server):
//   for (auto& a : timeline.Advance(sim_s, wall_s)) Carry(a);
//   // at shutdown: remove what is still active, newest first
//   for (auto& a : timeline.RemoveAll()) Carry(a);
//
// Clocks: `at` counts simulated time, `at_wall` wall time since the trial's Run, `on` fires at the
// first log line whose logfmt fields contain every `key=value` of the pattern (so
// "event=leader_elected" does not match event=leader_elected_late). A fault's duration runs on the
// clock it started on, and on the wall clock for `on` (the radio and Raft run on wall time).
// Each fault is applied at most once. Actions come out in schedule order within a call; removals
// before applications when both are due.
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>
#include <vector>

#include "swarmbox/faults/fault_spec.hpp"

namespace swarmbox::faults {

struct TimelineAction {
  enum class Kind { kApply, kRemove };
  Kind kind = Kind::kApply;
  std::size_t fault = 0;  // index into the schedule
  bool operator==(const TimelineAction&) const = default;
};

class FaultTimeline {
 public:
  explicit FaultTimeline(std::vector<Fault> faults);

  std::vector<TimelineAction> Advance(double sim_s, double wall_s);
  std::vector<TimelineAction> OnLogLine(std::string_view line, double wall_s);
  std::vector<TimelineAction> RemoveAll();

  const std::vector<Fault>& faults() const { return faults_; }
  bool active(std::size_t fault) const { return state_[fault].active; }

 private:
  struct State {
    bool applied = false;
    bool active = false;
    std::optional<double> remove_sim_s;
    std::optional<double> remove_wall_s;
    std::size_t order = 0;  // application order, for RemoveAll
  };
  // wall_s: now, for the end of an event-started fault's duration.
  void Apply(std::size_t i, double wall_s, std::vector<TimelineAction>* out);

  std::vector<Fault> faults_;
  std::vector<State> state_;
  std::size_t applied_count_ = 0;
};

// Whether a logfmt line has every key=value pair of `pattern` ("event=leader_elected",
// "event=victim_confirmed node=scout_2").
bool LogLineMatches(std::string_view line, std::string_view pattern);

}  // namespace swarmbox::faults
