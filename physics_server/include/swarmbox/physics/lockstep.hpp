// Lockstep: which drones answered which control step, and who is lost. Pure logic, no clock:
// the caller passes `now_ns` (any monotonic clock; tests use a fake one).
//
//   Lockstep ls(n, {.timeout_ns = 2'000'000'000});
//   ls.BeginStep(step, now);                 // samples for `step` published
//   ls.OnCommand(drone, step, now);          // commands arrive (late/early ones are rejected)
//   while (!ls.StepComplete(now)) wait();    // every live drone answered, or timed out
//   for (auto d : ls.TakeNewlyLost()) world.SetLost(d, true);
//
// A drone is lost when it has not answered the current step within timeout_ns of the later of
// (the step's start, its last answer). Before a drone's first answer, join_timeout_ns applies
// instead (agents start slower than the server), counted from the later of the step's start and
// the latest first answer of any drone: while drones keep joining (a 100-drone start takes
// seconds) nobody is given up; once none has joined for join_timeout_ns, the silent ones are
// lost. A lost drone that answers the current step rejoins (TakeRejoined()).
//
// Cost: OnCommand, StepComplete (until a deadline passes), NextDeadlineNs and awaited() are O(1)
// amortised; BeginStep, SetOut and a passed deadline are O(drones). A step of N answers is O(N),
// not O(N^2) (the server calls StepComplete and NextDeadlineNs after every arrival).
//
// A drone taken out of the trial (SetOut: a process fault of the radio plan) is neither waited for
// nor heard (its commands are kOut) until SetOut(false), when it re-enters as a joining drone:
// join_timeout_ns applies to its first answer again.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

namespace swarmbox::physics {

struct LockstepOptions {
  std::int64_t timeout_ns = 1'000'000'000;       // silence that marks a live drone lost
  std::int64_t join_timeout_ns = 30'000'000'000; // before its first answer, with no drone joining
};

class Lockstep {
 public:
  enum class Answer { kAccepted, kDuplicate, kWrongStep, kUnknownDrone, kOut };

  Lockstep(std::size_t drone_count, LockstepOptions options);

  void BeginStep(std::uint64_t step, std::int64_t now_ns);
  Answer OnCommand(std::size_t drone, std::uint64_t step, std::int64_t now_ns);
  // True when every live drone answered the current step; marks drones lost whose time ran out.
  bool StepComplete(std::int64_t now_ns);
  // The earliest time at which a waiting drone times out (for a bounded wait); INT64_MAX if none.
  std::int64_t NextDeadlineNs() const;
  // Live drones (neither lost nor out) that have not answered the current step.
  std::size_t awaited() const { return pending_; }

  // Out of the trial (true) or back as a joining drone (false; clears lost, answered and joined).
  void SetOut(std::size_t drone, bool out);

  std::vector<std::size_t> TakeNewlyLost();
  std::vector<std::size_t> TakeRejoined();
  bool lost(std::size_t drone) const { return drones_[drone].lost; }
  bool answered(std::size_t drone) const { return drones_[drone].answered; }
  bool joined(std::size_t drone) const { return drones_[drone].joined; }
  bool out(std::size_t drone) const { return drones_[drone].out; }
  std::uint64_t step() const { return step_; }
  std::size_t live_count() const;   // neither lost nor out
  std::size_t lost_count() const;

 private:
  struct DroneState {
    bool joined = false;
    bool answered = false;
    bool lost = false;
    bool out = false;
    std::int64_t last_heard_ns = 0;
  };
  bool Pending(const DroneState& d) const { return !d.lost && !d.answered && !d.out; }
  std::int64_t Deadline(const DroneState& d) const;
  // Recomputes pending_ and the earliest deadline (O(drones)).
  void Recount() const;

  LockstepOptions options_;
  std::vector<DroneState> drones_;
  // Cache over drones_ (kept by every mutator): the pending drones, their earliest deadline and
  // how many share it; `stale_`: that deadline's drones all answered, recompute before use.
  mutable std::size_t pending_ = 0;
  mutable std::int64_t next_deadline_ns_ = 0;
  mutable std::size_t at_next_deadline_ = 0;
  mutable bool stale_ = false;
  std::uint64_t step_ = 0;
  std::int64_t step_start_ns_ = 0;
  std::int64_t last_join_ns_ = std::numeric_limits<std::int64_t>::min();  // latest first answer
  std::int64_t JoinDeadlineNs() const;
  std::vector<std::size_t> newly_lost_;
  std::vector<std::size_t> rejoined_;
};

}  // namespace swarmbox::physics
