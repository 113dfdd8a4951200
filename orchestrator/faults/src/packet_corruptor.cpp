#include "swarmbox/faults/packet_corruptor.hpp"

#include "swarmbox/common/result.hpp"

namespace swarmbox::faults {

PacketCorruptor::PacketCorruptor(double probability, std::uint64_t seed)
    : probability_(probability), rng_(seed ^ 0x636f'7272'7570'7400ULL) {}  // "corrupt": its own stream

std::optional<std::size_t> PacketCorruptor::Choose(std::size_t length) {
  if (probability_ <= 0.0) return std::nullopt;
  const bool chosen = probability_ >= 1.0 || std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < probability_;
  if (!chosen || length == 0) return std::nullopt;
  const std::size_t byte = std::uniform_int_distribution<std::size_t>(0, length - 1)(rng_);
  const std::size_t bit = std::uniform_int_distribution<std::size_t>(0, 7)(rng_);
  return byte * 8 + bit;
}

void FlipBit(std::span<std::uint8_t> bytes, std::size_t bit) {
  SWARMBOX_CHECK(bit / 8 < bytes.size());
  bytes[bit / 8] = static_cast<std::uint8_t>(bytes[bit / 8] ^ (1u << (bit % 8)));
}

}  // namespace swarmbox::faults
