// LinkProbe over ChannelRadios and a scripted channel (fixed one-way delay, chosen drops): RTTs
// in simulated ms exactly, loss counted by the settling rule, pings answered with the ping's seq
// and sent_ns, pings and pongs for others ignored, bad arguments refused with the reason.
#include "swarmbox/radio/link_probe.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "swarmbox/radio/channel_radio.hpp"
#include "swarmbox/radio/link_event.hpp"

namespace swarmbox::radio {
namespace {

using namespace std::chrono_literals;

constexpr std::int64_t kStepNs = 4'000'000;

// A radio that records what is sent (for the answering rules).
class RecordingRadio final : public MeshRadio {
 public:
  void Send(bus::RadioFrame frame) override { sent.push_back(std::move(frame)); }
  void TakeReceived(const bus::SensorSample&, std::vector<bus::RadioFrame>*) override {}
  void Flush(bus::ActuatorCommand*) override {}
  std::int64_t now_ns() const override { return 0; }
  std::vector<bus::RadioFrame> sent;
};

bus::RadioFrame PingFrame(const std::string& from, const std::string& to, std::uint64_t seq, bool pong,
                          std::int64_t sent_ns, std::int64_t delivered_ns) {
  bus::RadioFrame f;
  f.from = from;
  f.to = to;
  f.delivered_ns = delivered_ns;
  bus::RadioPing p;
  p.from = from;
  p.to = to;
  p.seq = seq;
  p.sent_ns = sent_ns;
  p.is_pong = pong;
  f.ping_msg.push_back(p);
  return f;
}

// Two drones a and b in lockstep: each step every frame of radio_out is delivered `delay_ns`
// later unless `drop` says so, and handed over in the first step at or after its delivery.
struct TwoDrones {
  ChannelRadio ra{"a"}, rb{"b"};
  std::unique_ptr<LinkProbe> pa, pb;
  std::int64_t delay_ns = 100'000'000;
  std::function<bool(const bus::RadioFrame&)> drop = [](const bus::RadioFrame&) { return false; };
  std::multimap<std::int64_t, bus::RadioFrame> air;  // by delivery time
  std::vector<LinkLine> lines_a;

  TwoDrones() {
    pa = std::move(*LinkProbe::Create("a", {"a", "b"}, {}, RadioTime(0)));
    pb = std::move(*LinkProbe::Create("b", {"a", "b"}, {}, RadioTime(0)));
  }

  void Run(std::int64_t until_ns) {
    for (std::int64_t t = ra.now_ns(); t <= until_ns; t += kStepNs) Step(t);
  }

  void Step(std::int64_t t) {
    for (auto [radio, probe] : {std::pair{&ra, pa.get()}, std::pair{&rb, pb.get()}}) {
      bus::SensorSample s;
      s.sim_time_ns = t;
      for (auto it = air.begin(); it != air.end() && it->first <= t;) {
        if (it->second.to == radio->self()) {
          s.radio_in.push_back(it->second);
          it = air.erase(it);
        } else {
          ++it;
        }
      }
      std::vector<bus::RadioFrame> frames;
      radio->TakeReceived(s, &frames);
      for (const bus::RadioFrame& f : frames) probe->OnFrame(f, *radio);
      std::vector<LogEvent> lines;
      probe->Step(RadioTime(radio->now_ns()), static_cast<double>(t) * 1e-9, *radio, &lines);
      if (probe == pa.get()) {
        for (const LogEvent& e : lines) lines_a.push_back(*ParseLinkLine(e.str()));
      }
      bus::ActuatorCommand cmd;
      radio->Flush(&cmd);
      for (bus::RadioFrame& f : cmd.radio_out) {
        if (drop(f)) continue;
        f.delivered_ns = f.sent_ns + delay_ns;
        air.emplace(f.delivered_ns, f);
      }
    }
  }
};

TEST(LinkProbe, MeasuresRoundTripsInSimulatedMilliseconds) {
  TwoDrones d;  // 100 ms each way: every RTT is exactly 200 simulated ms
  d.Run(4'000'000'000);
  ASSERT_GE(d.lines_a.size(), 1u);
  const LinkLine& l = d.lines_a.back();
  EXPECT_EQ(l.node, "a");
  EXPECT_EQ(l.peer, "b");
  EXPECT_EQ(l.sent, 10u);  // 2 s window / 200 ms
  EXPECT_EQ(l.received, 10u);
  EXPECT_EQ(l.loss, 0.0);
  EXPECT_DOUBLE_EQ(l.rtt_ms_p50, 200.0);
  EXPECT_DOUBLE_EQ(l.rtt_ms_max, 200.0);
  EXPECT_DOUBLE_EQ(l.t_s, 4.0);
  EXPECT_EQ(d.pb->counters().pongs_sent, d.pa->counters().pings_sent - 1);  // the last is in flight
}

TEST(LinkProbe, CountsLossBothWays) {
  TwoDrones d;
  d.delay_ns = 48'000'000;
  // Drop a's 3rd ping and b's pong to a's 6th: two of the first ten lost.
  d.drop = [](const bus::RadioFrame& f) {
    const bus::RadioPing& p = f.ping_msg.front();
    return (!p.is_pong && p.from == "a" && p.seq == 3) || (p.is_pong && p.from == "b" && p.seq == 6);
  };
  d.Run(4'000'000'000);
  ASSERT_EQ(d.lines_a.size(), 2u);
  // Pings 1..20 (0 .. 3.8 s) are settled by 4 s, ping 21 (sent at 4 s) is still in flight; the
  // windows split them by the settling rule, but nothing is counted twice or dropped.
  EXPECT_EQ(d.lines_a[0].sent + d.lines_a[1].sent, 20u);
  EXPECT_EQ(d.lines_a[0].received + d.lines_a[1].received, 18u);
  EXPECT_DOUBLE_EQ(d.lines_a[0].rtt_ms_p50, 96.0);
  EXPECT_DOUBLE_EQ(d.lines_a[1].rtt_ms_max, 96.0);
}

TEST(LinkProbe, AnswersPingsToItselfAndIgnoresOthers) {
  auto probe = std::move(*LinkProbe::Create("b", {"a", "b", "c"}, {}, RadioTime(0)));
  RecordingRadio radio;
  probe->OnFrame(PingFrame("a", "b", 7, false, 123, 456), radio);
  ASSERT_EQ(radio.sent.size(), 1u);
  const bus::RadioFrame& f = radio.sent[0];
  EXPECT_EQ(f.to, "a");
  ASSERT_EQ(f.ping_msg.size(), 1u);
  EXPECT_EQ(f.ping_msg[0].from, "b");
  EXPECT_EQ(f.ping_msg[0].to, "a");
  EXPECT_EQ(f.ping_msg[0].seq, 7u);
  EXPECT_EQ(f.ping_msg[0].sent_ns, 123);
  EXPECT_TRUE(f.ping_msg[0].is_pong);
  // A ground station is answered too; a ping to c, our own ping and a pong we never asked for are not.
  probe->OnFrame(PingFrame("ground", "b", 1, false, 0, 0), radio);
  EXPECT_EQ(radio.sent.size(), 2u);
  probe->OnFrame(PingFrame("a", "c", 1, false, 0, 0), radio);
  probe->OnFrame(PingFrame("b", "b", 1, false, 0, 0), radio);
  probe->OnFrame(PingFrame("a", "b", 99, true, 0, 0), radio);
  EXPECT_EQ(radio.sent.size(), 2u);
  EXPECT_EQ(probe->counters().pongs_sent, 2u);
  EXPECT_EQ(probe->counters().pongs_received, 1u);
  EXPECT_EQ(probe->counters().ignored, 3u);
}

TEST(LinkProbe, PingsEveryPeerOnTheRadiosClock) {
  auto probe = std::move(*LinkProbe::Create("a", {"a", "b", "c"}, {.ping_every = 100ms}, RadioTime(0)));
  RecordingRadio radio;
  std::vector<LogEvent> lines;
  probe->Step(RadioTime(0), 0.0, radio, &lines);
  probe->Step(RadioTime(99'000'000), 0.099, radio, &lines);
  EXPECT_EQ(radio.sent.size(), 2u);
  probe->Step(RadioTime(100'000'000), 0.1, radio, &lines);
  ASSERT_EQ(radio.sent.size(), 4u);
  EXPECT_EQ(radio.sent[2].to, "b");
  EXPECT_EQ(radio.sent[3].to, "c");
  EXPECT_EQ(radio.sent[3].ping_msg[0].seq, 2u);
  EXPECT_EQ(radio.sent[3].ping_msg[0].sent_ns, 100'000'000);
  EXPECT_FALSE(radio.sent[3].ping_msg[0].is_pong);
  EXPECT_TRUE(lines.empty());
}

TEST(LinkProbe, PingsPingPeersPerRoundWhateverTheSwarmsSize) {
  // 100 members, 3 pings per round: 5 rounds a second cost 15 pings whatever the size; the peers
  // heard (any frame, here a state) come first.
  std::vector<std::string> members;
  for (int i = 1; i <= 100; ++i) members.push_back("scout_" + std::to_string(i));
  auto probe = std::move(*LinkProbe::Create("scout_1", members, {.ping_every = 200ms, .ping_peers = 3}, RadioTime(0)));
  bus::RadioFrame state;
  state.from = "scout_42";
  state.state_msg.resize(1);
  probe->Heard(state);
  RecordingRadio radio;
  std::vector<LogEvent> lines;
  for (std::int64_t t = 0; t < 1'000'000'000; t += kStepNs) probe->Step(RadioTime(t), 0.0, radio, &lines);
  ASSERT_EQ(radio.sent.size(), 15u);
  EXPECT_EQ(radio.sent[0].to, "scout_42");
  EXPECT_EQ(radio.sent[1].to, "scout_10");  // then the others by name: scout_10 < scout_100 < scout_11
  EXPECT_EQ(radio.sent[2].to, "scout_100");
  EXPECT_EQ(probe->counters().pings_sent, 15u);
}

TEST(LinkProbe, ReportsOnlyTheSampledPeers) {
  // A pinged peer that never answers gets loss=1 lines; a peer never pinged in a window, none.
  auto probe = std::move(*LinkProbe::Create("a", {"a", "b", "c", "d"}, {.ping_every = 1000ms, .ping_peers = 1},
                                            RadioTime(0)));
  RecordingRadio radio;
  std::vector<LogEvent> lines;
  for (std::int64_t t = 0; t <= 4'000'000'000; t += kStepNs) probe->Step(RadioTime(t), 0.0, radio, &lines);
  // Rounds at 0, 1, 2, 3, 4 s: b, c, d, b, c. Window (0, 2 s]: b settled lost at 1 s, c at 2 s;
  // window (2, 4 s]: d and b.
  ASSERT_EQ(radio.sent.size(), 5u);
  std::vector<std::string> peers;
  for (const LogEvent& l : lines) {
    auto parsed = ParseLinkLine(l.str());
    ASSERT_TRUE(parsed) << l.str();
    EXPECT_EQ(parsed->sent, 1u) << l.str();
    EXPECT_EQ(parsed->received, 0u) << l.str();
    peers.push_back(parsed->peer);
  }
  EXPECT_EQ(peers, (std::vector<std::string>{"b", "c", "b", "d"}));
}

TEST(LinkProbe, RefusesBadArguments) {
  auto none = LinkProbe::Create("a", {"a"}, {}, RadioTime(0));
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().ToString().find("no peer to ping"), std::string::npos);
  auto bad = LinkProbe::Create("a", {"b c"}, {}, RadioTime(0));
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().ToString().find("peer"), std::string::npos);
  auto zero = LinkProbe::Create("a", {"b"}, {.ping_every = 0ms}, RadioTime(0));
  ASSERT_FALSE(zero);
  EXPECT_NE(zero.error().ToString().find("must be positive"), std::string::npos);
  auto no_peers = LinkProbe::Create("a", {"b"}, {.ping_peers = 0}, RadioTime(0));
  ASSERT_FALSE(no_peers);
  EXPECT_NE(no_peers.error().ToString().find("ping_peers must be positive"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::radio
