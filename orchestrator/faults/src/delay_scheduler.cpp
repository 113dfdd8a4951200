#include "swarmbox/faults/delay_scheduler.hpp"

#include <algorithm>

#include "swarmbox/common/result.hpp"

namespace swarmbox::faults {
namespace {

// Seeds mt19937 from a 64-bit seed through splitmix64, so nearby seeds give unrelated streams.
std::uint32_t SeedWord(std::uint64_t seed) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return static_cast<std::uint32_t>((z ^ (z >> 31)) & 0xffffffffULL);
}

}  // namespace

DelayScheduler::DelayScheduler(const DelaySettings& settings, std::uint64_t seed)
    : settings_(settings),
      rng_(SeedWord(seed)),
      delay_random_(settings.correlation, rng_),
      reorder_random_(settings.reorder_correlation, rng_),
      reorder_threshold_(static_cast<std::uint32_t>(std::clamp(settings.reorder, 0.0, 1.0) * 4294967295.0)) {}

std::int64_t DelayScheduler::Admit(std::uint32_t id, std::int64_t now_us) {
  std::int64_t release_us = now_us;
  bool early = false;
  if (settings_.reorder > 0.0) {
    // netem_enqueue(): delayed when gap == 0 || counter < gap - 1 || reorder < get_crandom();
    // otherwise sent at once and the counter restarts.
    const std::uint32_t gap = settings_.reorder_gap == 0 ? 1 : settings_.reorder_gap;
    early = !(counter_ < gap - 1 || reorder_threshold_ < reorder_random_.Next());
  }
  if (early) {
    counter_ = 0;
    ++reordered_;
  } else {
    ++counter_;
    const std::uint32_t rnd = settings_.jitter_us > 0 ? delay_random_.Next() : 0U;
    release_us = now_us + SampleDelayUs(settings_.delay_us, settings_.jitter_us, settings_.distribution, rnd);
  }
  heap_.push(HeldPacket{id, release_us, now_us, sequence_++});
  return release_us;
}

std::optional<std::int64_t> DelayScheduler::NextReleaseUs() const {
  if (heap_.empty()) return std::nullopt;
  return heap_.top().release_us;
}

HeldPacket DelayScheduler::PopNext() {
  SWARMBOX_CHECK(!heap_.empty());
  HeldPacket p = heap_.top();
  heap_.pop();
  return p;
}

}  // namespace swarmbox::faults
