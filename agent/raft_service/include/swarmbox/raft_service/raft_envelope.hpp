// Raft envelope: the pure mapping between raft::Transport calls and bus::RaftMessage samples on
// the mesh radio topic (bus::kRaftTopic, Qos::kRadio). No DDS here: raft_radio.hpp does the I/O.
//
//   Send side:    bus::RaftMessage m = WrapRaftPayload("scout_1", "lifter", bytes);
//                 // m.from = "scout_1", m.to = "lifter", m.term = PeekRaftTerm(bytes), m.payload
//   Receive side: if (ClassifyRaftMessage(sample, "lifter") == RaftDelivery::kDeliver)
//                   driver.Receive(sample.payload);
//
// The payload is the raft message codec's bytes (message_codec.hpp), handed through untouched;
// the envelope's `term` is a copy of the codec's term read without decoding the whole message
// (diagnostics for bus recorders only: the receiver trusts the payload, never the envelope term).
// Thread-safety: free functions without state.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "swarmbox/bus/messages.hpp"

namespace swarmbox::raft_service {

// What a receiver does with a RaftMessage sample it heard on the radio topic.
enum class RaftDelivery : std::uint8_t {
  kDeliver,   // addressed to this drone by another drone, with a payload: hand it to Raft
  kNotForUs,  // addressed to another drone (the radio topic is shared by the whole swarm)
  kOwn,       // sent by this drone (a participant hears its own writer on the shared topic)
  kEmpty,     // no payload: nothing to deliver
};
std::string_view RaftDeliveryName(RaftDelivery d);  // "deliver", "not_for_us", "own", "empty"

// One envelope for one raft::Transport::Send(to, bytes) of drone `from`.
bus::RaftMessage WrapRaftPayload(std::string_view from, std::string_view to,
                                 std::span<const std::uint8_t> bytes);

// The term field of a codec-encoded raft message (version 1 layout: u8 version | fixed32 tag |
// u8 type | varint from | varint to | varint term ...), or 0 when `bytes` is too short, of
// another version or has a malformed varint.
std::uint64_t PeekRaftTerm(std::span<const std::uint8_t> bytes);

// Addressing rule of the receiver `self` (drone names compare exactly).
RaftDelivery ClassifyRaftMessage(const bus::RaftMessage& m, std::string_view self);

}  // namespace swarmbox::raft_service
