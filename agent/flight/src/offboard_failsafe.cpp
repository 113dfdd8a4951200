#include "swarmbox/flight/offboard_failsafe.hpp"

#include <cmath>
#include <limits>

#include "swarmbox/common/result.hpp"

namespace swarmbox::flight {
namespace {

// Silence within this of a threshold is at it, not past it [s] (see the header).
constexpr double kTimeTolerance_s = 1e-9;

}  // namespace

OffboardFailsafe::OffboardFailsafe(double timeout_s, double hold_s)
    : timeout_s_(timeout_s), hold_s_(hold_s), last_answer_s_(std::numeric_limits<double>::quiet_NaN()) {
  SWARMBOX_CHECK(std::isfinite(timeout_s) && timeout_s > 0.0);
  SWARMBOX_CHECK(std::isfinite(hold_s) && hold_s >= 0.0);
}

OffboardFailsafe::Action OffboardFailsafe::Update(double t_s, bool answered) {
  if (!started_) {
    started_ = true;
    last_answer_s_ = t_s;
  }
  if (action_ == Action::kLand) return action_;
  if (answered) {
    if (action_ == Action::kHold) {
      action_ = Action::kNone;
      Emit(EventKind::kRegained, t_s, t_s - last_answer_s_);
    }
    last_answer_s_ = t_s;
    return action_;
  }
  const double silent_s = t_s - last_answer_s_;
  if (action_ == Action::kNone && silent_s > timeout_s_ + kTimeTolerance_s) {
    action_ = Action::kHold;
    Emit(EventKind::kLost, t_s, silent_s);
  }
  if (action_ == Action::kHold && silent_s > timeout_s_ + hold_s_ + kTimeTolerance_s) {
    action_ = Action::kLand;
    Emit(EventKind::kFailsafe, t_s, silent_s);
  }
  return action_;
}

void OffboardFailsafe::Emit(EventKind kind, double t_s, double silent_s) {
  Event e;
  e.kind = kind;
  e.t_s = t_s;
  e.silent_s = silent_s;
  e.action = action_;
  events_.Push(e);  // full (nobody pops): the oldest is dropped
}

bool OffboardFailsafe::PopEvent(Event* out) {
  return events_.Pop(out);
}

std::string_view OffboardFailsafe::EventName(EventKind kind) {
  switch (kind) {
    case EventKind::kLost: return "offboard_lost";
    case EventKind::kFailsafe: return "offboard_failsafe";
    case EventKind::kRegained: return "offboard_regained";
  }
  return "unknown";
}

std::string_view OffboardFailsafe::ActionName(Action action) {
  switch (action) {
    case Action::kNone: return "none";
    case Action::kHold: return "hold";
    case Action::kLand: return "land";
  }
  return "unknown";
}

LogEvent OffboardFailsafe::ToLogEvent(const Event& e, std::string_view node) {
  // Field order as the design's lines (docs and tests match on them): offboard_lost silent_s=..
  // action=hold; offboard_failsafe action=land silent_s=..; offboard_regained silent_s=..
  LogEvent line(e.t_s, node, EventName(e.kind));
  switch (e.kind) {
    case EventKind::kLost: line.Add("silent_s", e.silent_s).Add("action", ActionName(e.action)); break;
    case EventKind::kFailsafe: line.Add("action", ActionName(e.action)).Add("silent_s", e.silent_s); break;
    case EventKind::kRegained: line.Add("silent_s", e.silent_s); break;
  }
  return line;
}

}  // namespace swarmbox::flight
