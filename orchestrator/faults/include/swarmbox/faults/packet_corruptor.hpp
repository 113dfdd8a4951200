// PacketCorruptor: netem's "corrupt P%" as a pure, seeded choice, for the userspace mechanism:
// swarmbox-netemd asks it about every queued packet and, when it names a bit, flips that bit in the
// packet's bytes and gives the verdict with the modified payload. As netem's netem_enqueue() does,
// a packet is chosen with probability P (independently: this project's spec has no corrupt
// correlation), then one byte uniformly in [0, length) and one bit of it uniformly in [0, 8).
// Checksums are not fixed (netem does not either): a receiver drops a UDP datagram whose checksum
// no longer matches (or an IP packet whose header checksum does not), which is the observable effect.
//
//   PacketCorruptor corrupt(/*probability=*/0.1, /*seed=*/42);
//   if (auto bit = corrupt.Choose(len)) FlipBit(bytes, *bit);
//
// Not thread-safe; the daemon's loop owns it. No allocation.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <random>
#include <span>

namespace swarmbox::faults {

class PacketCorruptor {
 public:
  PacketCorruptor(double probability, std::uint64_t seed);
  // For a packet of `length` bytes: the bit to flip (byte * 8 + bit, bit 0 = least significant), or
  // none to leave it whole. An empty packet is never corrupted (nothing to flip), but still draws.
  std::optional<std::size_t> Choose(std::size_t length);
  double probability() const { return probability_; }

 private:
  double probability_;
  std::mt19937_64 rng_;
};

// Flips bit `bit` (byte bit / 8, mask 1 << bit % 8) of `bytes`; aborts if it is out of range.
void FlipBit(std::span<std::uint8_t> bytes, std::size_t bit);

}  // namespace swarmbox::faults
