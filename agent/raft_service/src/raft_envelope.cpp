#include "swarmbox/raft_service/raft_envelope.hpp"

#include <string>

#include "swarmbox/raft/message_codec.hpp"

namespace swarmbox::raft_service {
namespace {

// Reads one LEB128 varint at `*pos`; false when truncated or longer than 10 bytes.
bool ReadVarint(std::span<const std::uint8_t> in, std::size_t* pos, std::uint64_t* out) {
  std::uint64_t v = 0;
  for (int shift = 0; shift < 64; shift += 7) {
    if (*pos >= in.size()) return false;
    const std::uint8_t b = in[(*pos)++];
    if (shift == 63 && b > 1) return false;
    v |= static_cast<std::uint64_t>(b & 0x7Fu) << shift;
    if ((b & 0x80u) == 0) {
      *out = v;
      return true;
    }
  }
  return false;
}

}  // namespace

std::string_view RaftDeliveryName(RaftDelivery d) {
  switch (d) {
    case RaftDelivery::kDeliver: return "deliver";
    case RaftDelivery::kNotForUs: return "not_for_us";
    case RaftDelivery::kOwn: return "own";
    case RaftDelivery::kEmpty: return "empty";
  }
  return "unknown";
}

bus::RaftMessage WrapRaftPayload(std::string_view from, std::string_view to,
                                 std::span<const std::uint8_t> bytes) {
  bus::RaftMessage m;
  m.from = std::string(from);
  m.to = std::string(to);
  m.term = PeekRaftTerm(bytes);
  m.payload.assign(bytes.begin(), bytes.end());
  return m;
}

std::uint64_t PeekRaftTerm(std::span<const std::uint8_t> bytes) {
  constexpr std::size_t kHeader = 1 + 4 + 1;  // version, cluster tag, type
  if (bytes.size() < kHeader || bytes[0] != raft::kWireVersion) return 0;
  std::size_t pos = kHeader;
  std::uint64_t from = 0, to = 0, term = 0;
  if (!ReadVarint(bytes, &pos, &from) || !ReadVarint(bytes, &pos, &to) ||
      !ReadVarint(bytes, &pos, &term)) {
    return 0;
  }
  return term;
}

RaftDelivery ClassifyRaftMessage(const bus::RaftMessage& m, std::string_view self) {
  if (m.from == self) return RaftDelivery::kOwn;
  if (m.to != self) return RaftDelivery::kNotForUs;
  if (m.payload.empty()) return RaftDelivery::kEmpty;
  return RaftDelivery::kDeliver;
}

}  // namespace swarmbox::raft_service
