#include "radio_dispatch.hpp"

#include "swarmbox/raft_service/raft_envelope.hpp"

namespace swarmbox::agent {
namespace {

// A frame's or a brain message's sender and addressee against this drone: false (counted as own
// or not for us) when it is not ours to take.
bool AddressedToUs(std::string_view from, std::string_view to, std::string_view self,
                   DispatchCounts* counts) {
  if (from == self) {
    ++counts->own;
    return false;
  }
  if (!to.empty() && to != self) {
    ++counts->not_for_us;
    return false;
  }
  return true;
}

// Exactly one of the five sequences holds exactly one element.
bool WellFormed(const bus::RadioFrame& f) {
  const int kinds = (f.state_msg.empty() ? 0 : 1) + (f.detection_msg.empty() ? 0 : 1) +
                    (f.raft_msg.empty() ? 0 : 1) + (f.ping_msg.empty() ? 0 : 1) +
                    (f.brain_msg.empty() ? 0 : 1);
  const std::size_t items = f.state_msg.size() + f.detection_msg.size() + f.raft_msg.size() +
                            f.ping_msg.size() + f.brain_msg.size();
  return kinds == 1 && items == 1;
}

void DispatchRaft(const bus::RaftMessage& m, std::string_view self, FrameHandler& handler,
                  DispatchCounts* counts) {
  switch (raft_service::ClassifyRaftMessage(m, self)) {
    case raft_service::RaftDelivery::kDeliver:
      ++counts->raft;
      handler.OnRaftPayload(m.payload);
      break;
    case raft_service::RaftDelivery::kOwn:
      ++counts->own;
      break;
    case raft_service::RaftDelivery::kNotForUs:
      ++counts->not_for_us;
      break;
    case raft_service::RaftDelivery::kEmpty:
      ++counts->malformed;
      break;
  }
}

// A well-formed frame addressed to us, by the one sequence it holds.
void DispatchFrame(const bus::RadioFrame& f, std::string_view self, FrameHandler& handler,
                   DispatchCounts* counts) {
  if (!f.raft_msg.empty()) {
    DispatchRaft(f.raft_msg.front(), self, handler, counts);
  } else if (!f.ping_msg.empty()) {
    ++counts->ping;
    handler.OnPing(f);
  } else if (!f.state_msg.empty()) {
    if (f.state_msg.front().drone == self) {
      ++counts->own;
      return;
    }
    ++counts->state;
    handler.OnState(f.state_msg.front(), f);
  } else if (!f.brain_msg.empty()) {
    const bus::BrainMessage& m = f.brain_msg.front();
    if (!AddressedToUs(m.from, m.to, self, counts)) return;
    ++counts->brain;
    handler.OnBrainMessage(m, f);
  } else {
    if (f.detection_msg.front().from == self) {
      ++counts->own;
      return;
    }
    ++counts->detection;
    handler.OnDetection(f.detection_msg.front(), f);
  }
}

}  // namespace

void DispatchFrames(std::span<const bus::RadioFrame> frames, std::string_view self, FrameHandler& handler,
                    DispatchCounts* counts) {
  for (const bus::RadioFrame& f : frames) {
    if (!AddressedToUs(f.from, f.to, self, counts)) continue;
    if (!WellFormed(f)) {
      ++counts->malformed;
      continue;
    }
    DispatchFrame(f, self, handler, counts);
  }
}

}  // namespace swarmbox::agent
