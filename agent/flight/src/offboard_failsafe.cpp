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
  if (ev_count_ == kEventCapacity) {  // nobody pops: drop the oldest
    ev_head_ = (ev_head_ + 1) % kEventCapacity;
    --ev_count_;
  }
  events_[(ev_head_ + ev_count_) % kEventCapacity] = e;
  ++ev_count_;
}

bool OffboardFailsafe::PopEvent(Event* out) {
  if (ev_count_ == 0) return false;
  *out = events_[ev_head_];
  ev_head_ = (ev_head_ + 1) % kEventCapacity;
  --ev_count_;
  return true;
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
  LogEvent line(e.t_s, node, EventName(e.kind));
  line.Add("silent_s", e.silent_s);
  if (e.kind != EventKind::kRegained) line.Add("action", ActionName(e.action));
  return line;
}

}  // namespace swarmbox::flight
