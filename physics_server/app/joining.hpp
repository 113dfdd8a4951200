// Joining: the physics server's account of a trial's start, while not every drone has answered
// its first step. A 100-drone start takes seconds (containers starting, DDS discovery); the
// account shows it progressing and names who is still missing:
//
//   t=0.000 node=physics event=joining joined=37 expected=101 missing=scout_16,scout_40,...,+54
//
// every `every_ns` of wall time while the first step waits (none when every drone answers within
// the first interval), published as well on the bus's sim/status topic (the agents' sign that the
// server is alive while they wait for their first sample), then once, when the first step
// completes (every drone answered, or the silent ones were declared lost), if it took a joining
// line or lost a drone (a quick, complete start prints nothing):
//
//   t=0.000 node=physics event=joined joined=101 expected=101 lost=0 wait_s=6.214
//
// JoiningClock is pure: fed the wall time, no clock or I/O of its own (SimServer reads its
// WallClock seam, as the lockstep does).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::physics {

struct JoiningStatus {
  std::size_t joined = 0;            // drones that answered the first step
  std::size_t expected = 0;          // drones in the trial
  std::vector<std::string> missing;  // the others, in drone order
};

// "a,b,c": at most `max_names` names, then ",+N" for the rest; "-" when none.
std::string MissingList(const std::vector<std::string>& missing, std::size_t max_names = 10);

// The logfmt lines above (`missing` shortened by MissingList).
LogEvent JoiningEvent(double t_s, const std::string& node, const JoiningStatus& status);
LogEvent JoinedEvent(double t_s, const std::string& node, const JoiningStatus& status, std::size_t lost,
                     double wait_s);

// When the next joining line is due.
class JoiningClock {
 public:
  // `every_ns`: wall time between lines (> 0).
  explicit JoiningClock(std::int64_t every_ns) : every_ns_(every_ns) {}

  // The first step's samples went out at wall `now_ns`.
  void Begin(std::int64_t now_ns);
  // True when a line is due at `now_ns` (then the next one is due every_ns after the one due);
  // false before Begin and after End.
  bool Due(std::int64_t now_ns);
  // The first step completed: no more lines. Returns the wall seconds it waited since Begin.
  double End(std::int64_t now_ns);
  bool active() const { return active_; }
  // Whether Due() said true since Begin.
  bool reported() const { return reported_; }

 private:
  std::int64_t every_ns_;
  std::int64_t begin_ns_ = 0;
  std::int64_t next_ns_ = 0;
  bool active_ = false;
  bool reported_ = false;
};

}  // namespace swarmbox::physics
