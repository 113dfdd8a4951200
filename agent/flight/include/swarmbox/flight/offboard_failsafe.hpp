// OffboardFailsafe: what the flight stack does when the setpoint stream of an offboard brain stops.
// PX4's offboard loss failsafe: after COM_OF_LOSS_T (default 1.0 s) without the stream, the
// action of COM_OBL_RC_ACT (hold, land, return...). Here: hold for hold_s, then land.
// Pure, on simulated time only: the caller says every step whether the brain answered this
// period; no clock is read here, so a run is the same at any speed.
//
//   OffboardFailsafe fs(1.0, 5.0);                // --offboard-timeout-ms 1000, --offboard-hold-ms 5000
//   each lockstep step k, at simulated t_k:
//     switch (fs.Update(t_k, brain_answered)) {   // the action in force after this step
//       case OffboardFailsafe::Action::kNone: apply the brain's output; break;
//       case OffboardFailsafe::Action::kHold: fly Setpoint::Hold() (once, when it starts); break;
//       case OffboardFailsafe::Action::kLand: fly Setpoint::Land() (once), ignore the brain; break;
//     }
//     OffboardFailsafe::Event e;
//     while (fs.PopEvent(&e)) puts(OffboardFailsafe::ToLogEvent(e, drone).str().c_str());
//
// The rule, with `silent_s` = t_s - the last step that answered (or the first Update, if none
// has: a brain that never answers is lost as well):
//   kNone, silent_s >  timeout_s          -> kHold; event offboard_lost silent_s=.. action=hold
//   kHold, an answer                      -> kNone; event offboard_regained silent_s=.. (the
//                                            silence that ended); the brain flies again
//   kHold, silent_s >  timeout_s + hold_s -> kLand; event offboard_failsafe action=land silent_s=..
//   kLand                                 -> kLand for good: answers are ignored (PX4 needs a new
//                                            mode switch to leave the failsafe; here, a new trial)
// An answer at a step resets the silence before the step is judged. A jump in t_s past both
// thresholds at once gives both events, lost first. Times within 1 ns of a threshold count as at
// it, not past it (t_s comes from integer nanoseconds; 3.000000000000001 - 2 is not > 1).
// Update and PopEvent neither allocate nor throw; not thread-safe (one owner, the agent's step).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/flight/detail/event_ring.hpp"

namespace swarmbox::flight {

class OffboardFailsafe {
 public:
  enum class Action : std::uint8_t {
    kNone,  // the brain's setpoints fly
    kHold,  // the stream is lost: hold where it is, waiting for it
    kLand,  // lost for too long: land; stays so
  };
  enum class EventKind : std::uint8_t { kLost, kFailsafe, kRegained };
  struct Event {
    EventKind kind = EventKind::kLost;
    double t_s = 0.0;       // simulated time of the Update that saw it [s]
    double silent_s = 0.0;  // time since the last answer then [s]
    Action action = Action::kNone;  // the action in force after it
  };

  // timeout_s > 0 (PX4 COM_OF_LOSS_T; the agent's --offboard-timeout-ms), hold_s >= 0 (the
  // agent's --offboard-hold-ms), both finite; aborts otherwise (the agent validates its flags).
  OffboardFailsafe(double timeout_s, double hold_s);

  // One step at simulated time t_s [s]; `answered`: the brain answered in this step. Returns the
  // action in force after it.
  Action Update(double t_s, bool answered);

  // Events since the last call, oldest first; false when none are left.
  bool PopEvent(Event* out);

  Action action() const { return action_; }
  double timeout_s() const { return timeout_s_; }
  double hold_s() const { return hold_s_; }
  // Time of the last answer (or of the first Update); NaN before the first Update.
  double last_answer_s() const { return last_answer_s_; }

  // "offboard_lost", "offboard_failsafe", "offboard_regained".
  static std::string_view EventName(EventKind kind);
  // "none", "hold", "land".
  static std::string_view ActionName(Action action);
  // The event's log line: `t=.. node=<node> event=offboard_lost silent_s=1.004 action=hold`,
  // `event=offboard_failsafe action=land silent_s=6.004`, `event=offboard_regained silent_s=1.500`.
  static LogEvent ToLogEvent(const Event& e, std::string_view node);

 private:
  void Emit(EventKind kind, double t_s, double silent_s);

  double timeout_s_;
  double hold_s_;
  Action action_ = Action::kNone;
  double last_answer_s_;
  bool started_ = false;

  detail::EventRing<Event, 8> events_;
};

}  // namespace swarmbox::flight
