#include "swarmbox/physics/lockstep.hpp"

#include <algorithm>
#include <limits>
#include <utility>

namespace swarmbox::physics {

Lockstep::Lockstep(std::size_t drone_count, LockstepOptions options) : options_(options), drones_(drone_count) {
  Recount();
}

std::int64_t Lockstep::Deadline(const DroneState& d) const {
  return d.joined ? std::max(step_start_ns_, d.last_heard_ns) + options_.timeout_ns : JoinDeadlineNs();
}

void Lockstep::Recount() const {
  std::size_t pending = 0;
  std::int64_t next = std::numeric_limits<std::int64_t>::max();
  std::size_t at_next = 0;
  for (const DroneState& d : drones_) {
    if (!Pending(d)) continue;
    ++pending;
    const std::int64_t deadline = Deadline(d);
    if (deadline < next) {
      next = deadline;
      at_next = 0;
    }
    if (deadline == next) ++at_next;
  }
  pending_ = pending;
  next_deadline_ns_ = next;
  at_next_deadline_ = at_next;
  stale_ = false;
}

void Lockstep::BeginStep(std::uint64_t step, std::int64_t now_ns) {
  step_ = step;
  step_start_ns_ = now_ns;
  for (DroneState& d : drones_) d.answered = false;
  Recount();
}

Lockstep::Answer Lockstep::OnCommand(std::size_t drone, std::uint64_t step, std::int64_t now_ns) {
  if (drone >= drones_.size()) return Answer::kUnknownDrone;
  if (step != step_) return Answer::kWrongStep;
  DroneState& d = drones_[drone];
  if (d.out) return Answer::kOut;
  if (d.answered) return Answer::kDuplicate;
  if (!d.lost) {  // it was pending: one fewer; the earliest deadline moves once all of its drones answered
    --pending_;
    if (Deadline(d) == next_deadline_ns_ && --at_next_deadline_ == 0) stale_ = true;
  }
  d.answered = true;
  if (!d.joined) {  // a first answer moves every joining drone's deadline (JoinDeadlineNs): recount
    last_join_ns_ = std::max(last_join_ns_, now_ns);
    stale_ = true;
  }
  d.joined = true;
  d.last_heard_ns = now_ns;
  if (d.lost) {
    d.lost = false;
    rejoined_.push_back(drone);
  }
  return Answer::kAccepted;
}

std::int64_t Lockstep::JoinDeadlineNs() const {
  return std::max(step_start_ns_, last_join_ns_) + options_.join_timeout_ns;
}

std::int64_t Lockstep::NextDeadlineNs() const {
  if (pending_ == 0) return std::numeric_limits<std::int64_t>::max();
  if (stale_) Recount();
  return next_deadline_ns_;
}

bool Lockstep::StepComplete(std::int64_t now_ns) {
  if (pending_ == 0) return true;
  if (now_ns < NextDeadlineNs()) return false;  // nobody's time ran out: no scan
  bool complete = true;
  for (std::size_t i = 0; i < drones_.size(); ++i) {
    DroneState& d = drones_[i];
    if (!Pending(d)) continue;
    if (now_ns >= Deadline(d)) {
      d.lost = true;
      newly_lost_.push_back(i);
    } else {
      complete = false;
    }
  }
  Recount();
  return complete;
}

void Lockstep::SetOut(std::size_t drone, bool out) {
  DroneState& d = drones_.at(drone);
  d.out = out;
  if (!out) d = DroneState{};
  Recount();
}

std::vector<std::size_t> Lockstep::TakeNewlyLost() { return std::exchange(newly_lost_, {}); }
std::vector<std::size_t> Lockstep::TakeRejoined() { return std::exchange(rejoined_, {}); }

std::size_t Lockstep::live_count() const {
  return static_cast<std::size_t>(std::count_if(drones_.begin(), drones_.end(), [](const DroneState& d) { return !d.lost && !d.out; }));
}

std::size_t Lockstep::lost_count() const {
  return static_cast<std::size_t>(std::count_if(drones_.begin(), drones_.end(), [](const DroneState& d) { return d.lost; }));
}

}  // namespace swarmbox::physics
