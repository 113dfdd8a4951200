// A counter-based random generator: every draw is a pure function of its key, so a draw does not
// depend on how many draws were made before it, or in which order (the channel's determinism).
// SplitMix64 (Steele, Lea, Flood 2014) as the mixing function, chained over the key's fields.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

namespace swarmbox::channel::detail {

inline std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// What a draw is for; part of the key, so the draws of one frame are independent.
enum class Purpose : std::uint64_t {
  kLoss = 1,
  kDuplicate = 2,
  kJitter = 3,      // + copy * 16
  kAccessWait = 4,  // + copy * 16
  kPer = 5,         // + copy * 16
  kShadowing = 6,
};

inline std::uint64_t PurposeCode(Purpose p, std::uint32_t copy = 0) {
  return static_cast<std::uint64_t>(p) + 16ULL * copy;
}

// The key (seed, purpose, from, seq, sent_ns, to) hashed to 64 bits.
inline std::uint64_t DrawHash(std::uint64_t seed, std::uint64_t purpose, std::uint64_t from, std::uint64_t seq,
                              std::int64_t sent_ns, std::uint64_t to) {
  std::uint64_t h = SplitMix64(seed);
  h = SplitMix64(h ^ purpose);
  h = SplitMix64(h ^ from);
  h = SplitMix64(h ^ seq);
  h = SplitMix64(h ^ static_cast<std::uint64_t>(sent_ns));
  h = SplitMix64(h ^ to);
  return h;
}

// Uniform in the open interval (0, 1).
inline double Uniform01(std::uint64_t h) {
  return (static_cast<double>(h >> 11) + 0.5) * 0x1.0p-53;
}

// Standard normal (Box-Muller on two uniforms derived from h).
inline double StandardNormal(std::uint64_t h) {
  const double u1 = Uniform01(h);
  const double u2 = Uniform01(SplitMix64(h ^ 0x5851f42d4c957f2dULL));
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace swarmbox::channel::detail
