// LatencyQueue: simulated inference latency. A detection made on a frame captured at t becomes
// visible to the rest of the agent at t + latency (default 40 ms, an OAK-D-class device); before
// that PopVisible() does not return it. Pure: the caller passes simulated time.
//
//   LatencyQueue q(0.040);
//   q.Push(detection, capture_time_s);          // sets capture_time_s / visible_time_s
//   q.PopVisible(now_s, &ready);                // appends the ones due, oldest first
//
// Fixed capacity (no allocation after construction, besides `out` growth): when full the oldest
// pending detection is dropped and counted in dropped().
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "swarmbox/swarm/detection.hpp"

namespace swarmbox::swarm {

class LatencyQueue {
 public:
  // latency_s >= 0, capacity >= 1 (aborts otherwise: configuration bug).
  explicit LatencyQueue(double latency_s = 0.040, std::size_t capacity = 64);

  void Push(GroundDetection detection, double capture_time_s);
  // Appends every detection with visible_time_s <= now_s, in visible-time order.
  void PopVisible(double now_s, std::vector<GroundDetection>* out);

  double latency_s() const { return latency_s_; }
  std::size_t pending() const { return size_; }
  std::uint64_t dropped() const { return dropped_; }

 private:
  double latency_s_;
  std::vector<GroundDetection> ring_;  // capacity slots
  std::size_t head_ = 0;               // oldest
  std::size_t size_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace swarmbox::swarm
