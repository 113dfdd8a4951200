// Raft messages to bytes and back, for the radio (one message per datagram / DDS sample).
//
// Layout (version 1), all integers LEB128 varints unless noted:
//   u8 version=1 | fixed32 cluster_tag | u8 type | from | to | term | log_term | index | commit |
//   u8 flags (bit0 reject) | reject_hint | entry count | entries... |
//   [kSnap: index term data conf]
//   entry := term | index | u8 type (0 normal, 1 no-op, 2 conf change) | data (length + bytes)
//   conf  := voter count | voters... | learner count | learners...   (ascending ids)
// cluster_tag (ClusterTag()) is a hash of the member names, so drones configured with different
// member lists refuse each other's messages instead of mixing up node ids.
//
// DecodeMessage never reads out of bounds and never aborts: any malformed input (wrong version,
// truncation, trailing bytes, a local message type, non-contiguous entries...) is a kProtocol
// error saying what and at which byte.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/types.hpp"

namespace swarmbox::raft {

inline constexpr std::uint8_t kWireVersion = 1;

// FNV-1a over the sorted member names, each followed by a 0 byte.
std::uint32_t ClusterTag(const std::vector<std::string>& sorted_names);

Bytes EncodeMessage(const Message& m, std::uint32_t cluster_tag);
Result<Message> DecodeMessage(std::span<const std::uint8_t> bytes, std::uint32_t cluster_tag);

}  // namespace swarmbox::raft
