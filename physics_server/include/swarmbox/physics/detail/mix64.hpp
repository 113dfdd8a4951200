// Mix64: splitmix64's finaliser, the physics server's one hash for seeded values that must be a
// function of their inputs alone (the stereo pair's read-noise seed, stereo_capture.cpp; the
// world scene's texture lattice, world_scene.cpp; the drawn bodies' texture, stereo_renderer.cpp).
// Changing it changes every rendered pair (the stereo tests' pair hashes).
#pragma once

#include <cstdint>

namespace swarmbox::physics::detail {

constexpr std::uint64_t Mix64(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xBF58476D1CE4E5B9ULL;
  x ^= x >> 27;
  x *= 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

}  // namespace swarmbox::physics::detail
