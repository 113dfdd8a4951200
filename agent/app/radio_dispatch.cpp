#include "radio_dispatch.hpp"

#include "swarmbox/raft_service/raft_envelope.hpp"

namespace swarmbox::agent {

void DispatchFrames(std::span<const bus::RadioFrame> frames, std::string_view self, FrameHandler& handler,
                    DispatchCounts* counts) {
  for (const bus::RadioFrame& f : frames) {
    if (f.from == self) {
      ++counts->own;
      continue;
    }
    if (!f.to.empty() && f.to != self) {
      ++counts->not_for_us;
      continue;
    }
    const int kinds = (f.state_msg.empty() ? 0 : 1) + (f.detection_msg.empty() ? 0 : 1) +
                      (f.raft_msg.empty() ? 0 : 1) + (f.ping_msg.empty() ? 0 : 1) + (f.brain_msg.empty() ? 0 : 1);
    const std::size_t items = f.state_msg.size() + f.detection_msg.size() + f.raft_msg.size() +
                              f.ping_msg.size() + f.brain_msg.size();
    if (kinds != 1 || items != 1) {
      ++counts->malformed;
      continue;
    }
    if (!f.raft_msg.empty()) {
      const bus::RaftMessage& m = f.raft_msg.front();
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
    } else if (!f.ping_msg.empty()) {
      ++counts->ping;
      handler.OnPing(f);
    } else if (!f.state_msg.empty()) {
      if (f.state_msg.front().drone == self) {
        ++counts->own;
        continue;
      }
      ++counts->state;
      handler.OnState(f.state_msg.front(), f);
    } else if (!f.brain_msg.empty()) {
      const bus::BrainMessage& m = f.brain_msg.front();
      if (m.from == self) {
        ++counts->own;
        continue;
      }
      if (!m.to.empty() && m.to != self) {
        ++counts->not_for_us;
        continue;
      }
      ++counts->brain;
      handler.OnBrainMessage(m, f);
    } else {
      if (f.detection_msg.front().from == self) {
        ++counts->own;
        continue;
      }
      ++counts->detection;
      handler.OnDetection(f.detection_msg.front(), f);
    }
  }
}

}  // namespace swarmbox::agent
