#include "swarmbox/physics/lockstep.hpp"

#include <algorithm>
#include <limits>
#include <utility>

namespace swarmbox::physics {

Lockstep::Lockstep(std::size_t drone_count, LockstepOptions options) : options_(options), drones_(drone_count) {}

void Lockstep::BeginStep(std::uint64_t step, std::int64_t now_ns) {
  step_ = step;
  step_start_ns_ = now_ns;
  for (DroneState& d : drones_) d.answered = false;
}

Lockstep::Answer Lockstep::OnCommand(std::size_t drone, std::uint64_t step, std::int64_t now_ns) {
  if (drone >= drones_.size()) return Answer::kUnknownDrone;
  if (step != step_) return Answer::kWrongStep;
  DroneState& d = drones_[drone];
  if (d.out) return Answer::kOut;
  if (d.answered) return Answer::kDuplicate;
  d.answered = true;
  if (!d.joined) last_join_ns_ = std::max(last_join_ns_, now_ns);
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
  std::int64_t next = std::numeric_limits<std::int64_t>::max();
  for (const DroneState& d : drones_) {
    if (d.lost || d.answered || d.out) continue;
    const std::int64_t deadline = d.joined ? std::max(step_start_ns_, d.last_heard_ns) + options_.timeout_ns
                                           : JoinDeadlineNs();
    next = std::min(next, deadline);
  }
  return next;
}

bool Lockstep::StepComplete(std::int64_t now_ns) {
  bool complete = true;
  for (std::size_t i = 0; i < drones_.size(); ++i) {
    DroneState& d = drones_[i];
    if (d.lost || d.answered || d.out) continue;
    const std::int64_t deadline = d.joined ? std::max(step_start_ns_, d.last_heard_ns) + options_.timeout_ns
                                           : JoinDeadlineNs();
    if (now_ns >= deadline) {
      d.lost = true;
      newly_lost_.push_back(i);
    } else {
      complete = false;
    }
  }
  return complete;
}

void Lockstep::SetOut(std::size_t drone, bool out) {
  DroneState& d = drones_.at(drone);
  d.out = out;
  if (!out) d = DroneState{};
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
