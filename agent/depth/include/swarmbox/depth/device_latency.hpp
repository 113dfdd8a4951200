// DeviceLatency: the depth camera's own delay from exposure to depth on the host, on simulated
// time. The OAK-D Pro computes depth on its chip and delivers it 30-50 ms after the exposure
// (issue #23's figure; StereoSpec latency_min_ms/latency_max_ms): each frame draws its latency
// uniformly in [min, max] from a seeded generator, and frames leave in capture order (a pipeline:
// a frame is never released before the one captured before it).
//
//   DeviceLatency<DepthSummary> device(30, 50, /*seed=*/drone_seed);
//   device.Push(frame_time_ns, summary);
//   while (auto ready = device.Pop(now_ns)) Publish(*ready);   // now_ns: simulated time
//
// Pure: no wall clock; the same seed and times give the same releases.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <random>
#include <utility>

namespace swarmbox::depth {

template <typename T>
class DeviceLatency {
 public:
  DeviceLatency(double min_ms, double max_ms, std::uint64_t seed)
      : min_ns_(static_cast<std::int64_t>(min_ms * 1e6)), max_ns_(static_cast<std::int64_t>(max_ms * 1e6)), rng_(seed) {}

  // A frame exposed at capture_ns; returns the simulated time it will be released at.
  std::int64_t Push(std::int64_t capture_ns, T value) {
    std::uniform_int_distribution<std::int64_t> delay(min_ns_, max_ns_);
    std::int64_t release = capture_ns + delay(rng_);
    if (!queue_.empty()) release = std::max(release, queue_.back().first);
    queue_.emplace_back(release, std::move(value));
    return release;
  }

  // The oldest frame whose release time is at or before now_ns, if any.
  std::optional<T> Pop(std::int64_t now_ns) {
    if (queue_.empty() || queue_.front().first > now_ns) return std::nullopt;
    std::optional<T> out(std::move(queue_.front().second));
    queue_.pop_front();
    return out;
  }

  // The release time of the oldest frame still queued.
  std::optional<std::int64_t> NextRelease() const {
    if (queue_.empty()) return std::nullopt;
    return queue_.front().first;
  }
  std::size_t pending() const { return queue_.size(); }

 private:
  std::int64_t min_ns_, max_ns_;
  std::mt19937_64 rng_;
  std::deque<std::pair<std::int64_t, T>> queue_;
};

}  // namespace swarmbox::depth
