#include "swarmbox/swarm/latency_queue.hpp"

#include <utility>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {

LatencyQueue::LatencyQueue(double latency_s, std::size_t capacity)
    : latency_s_(latency_s), ring_(capacity) {
  SWARMBOX_CHECK(latency_s >= 0 && capacity >= 1);
}

void LatencyQueue::Push(GroundDetection detection, double capture_time_s) {
  detection.capture_time_s = capture_time_s;
  detection.visible_time_s = capture_time_s + latency_s_;
  if (size_ == ring_.size()) {  // full: drop the oldest
    head_ = (head_ + 1) % ring_.size();
    --size_;
    ++dropped_;
  }
  // Keep visible-time order (frames normally arrive in capture order: this is an append).
  std::size_t pos = size_;
  while (pos > 0 && ring_[(head_ + pos - 1) % ring_.size()].visible_time_s > detection.visible_time_s) {
    ring_[(head_ + pos) % ring_.size()] = ring_[(head_ + pos - 1) % ring_.size()];
    --pos;
  }
  ring_[(head_ + pos) % ring_.size()] = std::move(detection);
  ++size_;
}

void LatencyQueue::PopVisible(double now_s, std::vector<GroundDetection>* out) {
  while (size_ > 0 && ring_[head_].visible_time_s <= now_s) {
    out->push_back(ring_[head_]);
    head_ = (head_ + 1) % ring_.size();
    --size_;
  }
}

}  // namespace swarmbox::swarm
