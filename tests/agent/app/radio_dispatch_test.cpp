// DispatchFrames: each delivered frame goes to its one consumer in delivery order; our own
// frames, frames for other drones and malformed ones are dropped and counted.
#include "radio_dispatch.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "swarmbox/raft_service/raft_envelope.hpp"

namespace swarmbox::agent {
namespace {

class Recorder final : public FrameHandler {
 public:
  void OnRaftPayload(std::span<const std::uint8_t> bytes) override {
    calls.push_back("raft:" + std::to_string(bytes.size()));
  }
  void OnPing(const bus::RadioFrame& f) override { calls.push_back("ping:" + f.from); }
  void OnState(const bus::DroneState& s, const bus::RadioFrame& f) override {
    calls.push_back("state:" + s.drone + "@" + std::to_string(f.delivered_ns));
  }
  void OnDetection(const bus::Detection& d, const bus::RadioFrame&) override {
    calls.push_back("detection:" + d.from);
  }
  void OnBrainMessage(const bus::BrainMessage& m, const bus::RadioFrame&) override {
    calls.push_back("brain:" + m.from + ">" + m.to + ":" + m.topic);
  }
  std::vector<std::string> calls;
};

bus::RadioFrame State(const std::string& from, std::int64_t delivered_ns = 0) {
  bus::RadioFrame f;
  f.from = from;
  f.delivered_ns = delivered_ns;
  bus::DroneState s;
  s.drone = from;
  f.state_msg.push_back(s);
  return f;
}

bus::RadioFrame Raft(const std::string& from, const std::string& to, std::size_t bytes) {
  bus::RadioFrame f;
  f.from = from;
  f.to = to;
  f.raft_msg.push_back(raft_service::WrapRaftPayload(from, to, std::vector<std::uint8_t>(bytes, 7)));
  return f;
}

bus::RadioFrame Ping(const std::string& from, const std::string& to) {
  bus::RadioFrame f;
  f.from = from;
  f.to = to;
  bus::RadioPing p;
  p.from = from;
  p.to = to;
  f.ping_msg.push_back(p);
  return f;
}

bus::RadioFrame Brain(const std::string& from, const std::string& to, const std::string& topic) {
  bus::RadioFrame f;
  f.from = from;
  f.to = to;
  bus::BrainMessage m;
  m.from = from;
  m.to = to;
  m.topic = topic;
  m.payload = {1, 2, 3};
  f.brain_msg.push_back(m);
  return f;
}

TEST(RadioDispatch, HandsEachFrameToItsConsumerInDeliveryOrder) {
  bus::RadioFrame det;
  det.from = "scout_3";
  det.detection_msg.emplace_back();
  det.detection_msg[0].from = "scout_3";
  const std::vector<bus::RadioFrame> frames = {State("scout_2", 5), Raft("scout_3", "scout_1", 12),
                                               Brain("scout_3", "", "rv/vote"), Ping("scout_2", "scout_1"),
                                               det, Brain("lifter", "scout_1", "rv/ack"), State("lifter", 6)};
  Recorder r;
  DispatchCounts c;
  DispatchFrames(frames, "scout_1", r, &c);
  EXPECT_EQ(r.calls, (std::vector<std::string>{"state:scout_2@5", "raft:12", "brain:scout_3>:rv/vote", "ping:scout_2",
                                               "detection:scout_3", "brain:lifter>scout_1:rv/ack", "state:lifter@6"}));
  EXPECT_EQ(c, (DispatchCounts{.raft = 1, .ping = 1, .state = 2, .detection = 1, .brain = 2}));
}

TEST(RadioDispatch, DropsOwnForeignAndMalformedFrames) {
  bus::RadioFrame two_kinds = State("scout_2");
  two_kinds.ping_msg.emplace_back();
  bus::RadioFrame two_states = State("scout_2");
  two_states.state_msg.push_back(two_states.state_msg[0]);
  bus::RadioFrame empty;
  empty.from = "scout_2";
  bus::RadioFrame own_state = State("scout_2");
  own_state.state_msg[0].drone = "scout_1";  // relayed, but ours
  bus::RadioFrame own_brain = Brain("scout_2", "", "rv");
  own_brain.brain_msg[0].from = "scout_1";  // relayed, but ours
  bus::RadioFrame brain_for_other = Brain("scout_2", "", "rv");
  brain_for_other.brain_msg[0].to = "lifter";  // a broadcast frame holding a message for another drone
  const std::vector<bus::RadioFrame> frames = {
      State("scout_1"),               // our own broadcast
      Raft("scout_2", "scout_3", 4),  // addressed to another drone
      Ping("scout_2", "lifter"),      // likewise
      Raft("scout_2", "scout_1", 0),  // a Raft envelope without payload
      two_kinds,
      two_states,
      empty,
      own_state,
      Brain("scout_1", "", "rv"),       // our own brain's broadcast
      Brain("scout_2", "lifter", "rv"),  // addressed to another drone
      own_brain,
      brain_for_other};
  Recorder r;
  DispatchCounts c;
  DispatchFrames(frames, "scout_1", r, &c);
  EXPECT_TRUE(r.calls.empty());
  EXPECT_EQ(c, (DispatchCounts{.own = 4, .not_for_us = 4, .malformed = 4}));
}

TEST(RadioDispatch, DeliversRaftEnvelopesWhoseFrameHasNoSender) {
  // DdsRadio's Raft frames: RaftRadio hands over the payload only, addressed to us.
  bus::RadioFrame f;
  f.to = "scout_1";
  bus::RaftMessage m;
  m.to = "scout_1";
  m.payload = {1, 2};
  f.raft_msg.push_back(m);
  Recorder r;
  DispatchCounts c;
  DispatchFrames(std::vector<bus::RadioFrame>{f}, "scout_1", r, &c);
  EXPECT_EQ(r.calls, std::vector<std::string>{"raft:2"});
}

}  // namespace
}  // namespace swarmbox::agent
