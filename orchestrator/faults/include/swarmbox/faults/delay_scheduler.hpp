// DelayScheduler: the pure core of swarmbox-netemd, the userspace delayer (no sockets, no clock).
//
// Each queued packet is admitted with the current time and gets a release time: now + a delay drawn
// like netem's (delay_us +- jitter_us shaped by the distribution, correlated as netem correlates),
// or now for the `reorder` fraction (netem: with gap G, after G-1 delayed packets the next one goes
// at once with probability reorder, correlated by reorder_correlation). Held packets sit in a
// min-heap by release time (ties in arrival order), so jitter larger than the packet spacing
// reorders them as netem's tfifo does.
//
//   DelayScheduler s(settings, /*seed=*/42);
//   s.Admit(packet_id, now_us);                      // on every queued packet
//   while (auto t = s.NextReleaseUs(); t && *t <= now_us) accept(s.PopNext());
//
// Not thread-safe; the daemon's loop owns it. Admit/PopNext are O(log n) and allocate only when the
// heap grows.
#pragma once

#include <cstdint>
#include <optional>
#include <queue>
#include <random>
#include <vector>

#include "swarmbox/faults/netem_random.hpp"
#include "swarmbox/faults/netem_spec.hpp"

namespace swarmbox::faults {

struct DelaySettings {
  std::int64_t delay_us = 0;
  std::int64_t jitter_us = 0;
  DelayDistribution distribution = DelayDistribution::kUniform;
  double correlation = 0.0;  // delay correlation [0, 1]
  double reorder = 0.0;      // [0, 1]
  double reorder_correlation = 0.0;
  std::uint32_t reorder_gap = 0;  // 0 = 1 (netem's default when reorder is set)
  bool operator==(const DelaySettings&) const = default;
};

struct HeldPacket {
  std::uint32_t id = 0;           // the queue's packet id
  std::int64_t release_us = 0;    // when to accept it
  std::int64_t admitted_us = 0;
  std::uint64_t sequence = 0;     // arrival order, breaks ties
};

class DelayScheduler {
 public:
  DelayScheduler(const DelaySettings& settings, std::uint64_t seed);

  // Schedules packet `id` that arrived at now_us; returns its release time [us].
  std::int64_t Admit(std::uint32_t id, std::int64_t now_us);
  // The earliest release time held, if any.
  std::optional<std::int64_t> NextReleaseUs() const;
  // Removes and returns the packet with the earliest release time. Precondition: !empty().
  HeldPacket PopNext();

  bool empty() const { return heap_.empty(); }
  std::size_t size() const { return heap_.size(); }
  std::uint64_t admitted() const { return sequence_; }
  std::uint64_t reordered() const { return reordered_; }
  const DelaySettings& settings() const { return settings_; }

 private:
  struct Later {
    bool operator()(const HeldPacket& a, const HeldPacket& b) const {
      return a.release_us != b.release_us ? a.release_us > b.release_us : a.sequence > b.sequence;
    }
  };

  DelaySettings settings_;
  std::mt19937 rng_;
  CorrelatedUniform delay_random_;
  CorrelatedUniform reorder_random_;
  std::uint32_t reorder_threshold_;
  std::uint32_t counter_ = 0;  // packets since the last one sent early (netem's q->counter)
  std::uint64_t sequence_ = 0;
  std::uint64_t reordered_ = 0;
  std::priority_queue<HeldPacket, std::vector<HeldPacket>, Later> heap_;
};

}  // namespace swarmbox::faults
