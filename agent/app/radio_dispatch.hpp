// Radio dispatch: where each frame the MeshRadio delivered at a step goes, in delivery order
// (design: the time line of one lockstep step, 2b). Pure: no bus, no clock.
//
//   DispatchCounts counts;
//   DispatchFrames(frames, "scout_1", handler, &counts);
//     raft_msg addressed to us by another drone  -> handler.OnRaftPayload(payload)  (RaftService)
//     ping_msg                                   -> handler.OnPing(frame)           (LinkProbe)
//     state_msg of another drone                 -> handler.OnState(state, frame)   (mission peers)
//     detection_msg of another drone             -> handler.OnDetection(det, frame)
//     brain_msg of another drone                 -> handler.OnBrainMessage(msg, frame) (the brain's inbox)
//
// Dropped and counted: our own frames (from == self, or a state of ours), frames addressed to
// another drone (to neither "" nor self; a Raft envelope to another drone), and malformed frames
// (not exactly one of the five sequences holding exactly one element, a Raft envelope without a
// payload). The handler's calls come in the frames' order; nothing is reordered here.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "swarmbox/bus/messages.hpp"

namespace swarmbox::agent {

class FrameHandler {
 public:
  virtual ~FrameHandler() = default;
  virtual void OnRaftPayload(std::span<const std::uint8_t> bytes) = 0;
  virtual void OnPing(const bus::RadioFrame& frame) = 0;
  virtual void OnState(const bus::DroneState& state, const bus::RadioFrame& frame) = 0;
  virtual void OnDetection(const bus::Detection& detection, const bus::RadioFrame& frame) = 0;
  virtual void OnBrainMessage(const bus::BrainMessage& message, const bus::RadioFrame& frame) = 0;
};

struct DispatchCounts {
  std::uint64_t raft = 0;
  std::uint64_t ping = 0;
  std::uint64_t state = 0;
  std::uint64_t detection = 0;
  std::uint64_t brain = 0;
  std::uint64_t own = 0;
  std::uint64_t not_for_us = 0;
  std::uint64_t malformed = 0;
  bool operator==(const DispatchCounts&) const = default;
};

void DispatchFrames(std::span<const bus::RadioFrame> frames, std::string_view self, FrameHandler& handler,
                    DispatchCounts* counts);

}  // namespace swarmbox::agent
