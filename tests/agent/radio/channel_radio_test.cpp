// ChannelRadio: Send stamps from/seq/sent_ns/size_bytes and queues, TakeReceived hands the
// sample's radio_in over in its order and sets the clock, Flush moves the queue into radio_out.
#include "swarmbox/radio/channel_radio.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace swarmbox::radio {
namespace {

bus::RadioFrame StateFrame(const std::string& to = "") {
  bus::RadioFrame f;
  f.to = to;
  bus::DroneState s;
  s.drone = "scout_1";
  s.mode = "scout/searching";
  f.state_msg.push_back(s);
  return f;
}

bus::SensorSample SampleAt(std::int64_t ns) {
  bus::SensorSample s;
  s.drone = "scout_1";
  s.sim_time_ns = ns;
  return s;
}

TEST(ChannelRadio, SendStampsTheFrameWithTheStepsSimulatedTime) {
  ChannelRadio radio("scout_1");
  std::vector<bus::RadioFrame> in;
  radio.TakeReceived(SampleAt(4'000'000), &in);
  EXPECT_EQ(radio.now_ns(), 4'000'000);
  bus::RadioFrame f = StateFrame();
  f.from = "forged";
  f.seq = 99;
  f.delivered_ns = 7;
  radio.Send(f);
  radio.Send(StateFrame("scout_2"));
  ASSERT_EQ(radio.queued(), 2u);
  bus::ActuatorCommand cmd;
  radio.Flush(&cmd);
  ASSERT_EQ(cmd.radio_out.size(), 2u);
  EXPECT_EQ(cmd.radio_out[0].from, "scout_1");
  EXPECT_EQ(cmd.radio_out[0].seq, 1u);
  EXPECT_EQ(cmd.radio_out[0].sent_ns, 4'000'000);
  EXPECT_EQ(cmd.radio_out[0].delivered_ns, 0);
  EXPECT_EQ(cmd.radio_out[0].size_bytes, FrameBytes(cmd.radio_out[0]));
  EXPECT_GT(cmd.radio_out[0].size_bytes, 106u);  // headers plus the state
  EXPECT_EQ(cmd.radio_out[1].seq, 2u);
  EXPECT_EQ(cmd.radio_out[1].to, "scout_2");
  EXPECT_EQ(radio.sent(), 2u);
}

TEST(ChannelRadio, CarriesBrainMessagesAndChargesTheirBytes) {
  ChannelRadio radio("scout_1");
  std::vector<bus::RadioFrame> in;
  bus::SensorSample sample = SampleAt(8'000'000);
  bus::RadioFrame heard;
  heard.from = "scout_2";
  heard.delivered_ns = 8'000'000;
  heard.brain_msg.push_back({"scout_2", "", "rendezvous/vote", {1, 2, 3}});
  sample.radio_in.push_back(heard);
  radio.TakeReceived(sample, &in);
  ASSERT_EQ(in.size(), 1u);
  EXPECT_EQ(in[0], heard);
  bus::RadioFrame f;
  f.brain_msg.push_back({"scout_1", "", "rendezvous/vote", std::vector<std::uint8_t>(100, 7)});
  radio.Send(f);
  f.brain_msg[0].payload.resize(300);
  radio.Send(f);
  bus::ActuatorCommand cmd;
  radio.Flush(&cmd);
  ASSERT_EQ(cmd.radio_out.size(), 2u);
  EXPECT_EQ(cmd.radio_out[0].brain_msg[0].topic, "rendezvous/vote");
  EXPECT_EQ(cmd.radio_out[0].sent_ns, 8'000'000);
  // The payload is on the air: 200 more bytes cost 200 more bytes of airtime.
  EXPECT_EQ(cmd.radio_out[1].size_bytes - cmd.radio_out[0].size_bytes, 200u);
  EXPECT_GT(cmd.radio_out[0].size_bytes, 106u + 100u);
}

TEST(ChannelRadio, FlushReplacesRadioOutAndEmptiesTheQueue) {
  ChannelRadio radio("scout_1");
  bus::ActuatorCommand cmd;
  cmd.radio_out.push_back(StateFrame());  // last step's frames must not go out twice
  radio.Flush(&cmd);
  EXPECT_TRUE(cmd.radio_out.empty());
  radio.Send(StateFrame());
  radio.Flush(&cmd);
  EXPECT_EQ(cmd.radio_out.size(), 1u);
  EXPECT_EQ(radio.queued(), 0u);
  radio.Flush(&cmd);
  EXPECT_TRUE(cmd.radio_out.empty());
}

TEST(ChannelRadio, TakeReceivedAppendsRadioInInTheChannelsOrder) {
  ChannelRadio radio("scout_2");
  bus::SensorSample s = SampleAt(8'000'000);
  for (std::uint64_t seq : {3u, 1u, 2u}) {  // the channel's order, kept as it is
    bus::RadioFrame f = StateFrame();
    f.seq = seq;
    f.delivered_ns = 7'000'000 + static_cast<std::int64_t>(seq);
    s.radio_in.push_back(f);
  }
  std::vector<bus::RadioFrame> out(1);  // appends
  radio.TakeReceived(s, &out);
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out[1].seq, 3u);
  EXPECT_EQ(out[2].seq, 1u);
  EXPECT_EQ(out[3].seq, 2u);
  EXPECT_EQ(radio.now_ns(), 8'000'000);
}

}  // namespace
}  // namespace swarmbox::radio
