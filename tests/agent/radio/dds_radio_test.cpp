// DdsRadio over real DDS (Cyclone DDS on lo, in one process; integration), driven as the agent's
// control loop drives it (TakeReceived, the LinkProbe, Send; every 5 ms of wall time): two drones
// see a clean fast link, hear each other's DroneStates and Raft payloads addressed to them, a
// third drone's traffic is not counted, a missing peer is reported lost, bad arguments fail with
// the reason, brain messages reach their addressees. DDS domains 224-226.
#include "swarmbox/radio/dds_radio.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "swarmbox/radio/link_event.hpp"
#include "swarmbox/radio/link_probe.hpp"

namespace swarmbox::radio {
namespace {

using namespace std::chrono_literals;

std::unique_ptr<bus::Participant> Mesh(int domain) {
  auto p = bus::Participant::Create({.backend = "cyclonedds", .domain_id = domain, .interface = "lo"});
  EXPECT_TRUE(p) << p.error().ToString();
  return p ? std::move(*p) : nullptr;
}

LinkProbeOptions Fast() {
  return LinkProbeOptions{.ping_every = 50ms, .timeout = 500ms, .report_every = 1000ms};
}

struct Drone {
  std::string name;
  std::unique_ptr<bus::Participant> mesh;
  std::unique_ptr<DdsRadio> radio;
  std::unique_ptr<LinkProbe> probe;
  std::vector<LinkLine> lines;
  std::map<std::string, int> states_from;
  std::vector<std::vector<std::uint8_t>> raft_payloads;
  std::vector<bus::RadioFrame> frames;

  Drone(int domain, std::string n, std::vector<std::string> members, std::vector<std::string> ping)
      : name(std::move(n)), mesh(Mesh(domain)) {
    if (!mesh) return;
    auto r =
        DdsRadio::Create(*mesh, name, {.members = members, .raft = true, .pings = true, .hear_states = true});
    EXPECT_TRUE(r) << r.error().ToString();
    if (r) radio = std::move(*r);
    auto p = LinkProbe::Create(name, ping, Fast(), RadioTime(radio ? radio->now_ns() : 0));
    EXPECT_TRUE(p) << p.error().ToString();
    if (p) probe = std::move(*p);
  }

  // One control step.
  void Step(double sim_t_s, bool broadcast) {
    frames.clear();
    radio->TakeReceived(bus::SensorSample{}, &frames);
    for (const bus::RadioFrame& f : frames) {
      EXPECT_GE(f.delivered_ns, 0);
      if (!f.ping_msg.empty()) probe->OnFrame(f, *radio);
      if (!f.state_msg.empty()) ++states_from[f.state_msg[0].drone];
      if (!f.raft_msg.empty()) {
        EXPECT_EQ(f.raft_msg[0].to, name);
        raft_payloads.push_back(f.raft_msg[0].payload);
      }
    }
    std::vector<LogEvent> out;
    probe->Step(RadioTime(radio->now_ns()), sim_t_s, *radio, &out);
    for (const LogEvent& e : out) lines.push_back(*ParseLinkLine(e.str()));
    if (broadcast) {
      bus::RadioFrame f;
      bus::DroneState s;
      s.drone = name;
      f.state_msg.push_back(s);
      radio->Send(f);
    }
  }
};

void RunFor(std::vector<Drone*> drones, std::chrono::milliseconds duration,
            const std::function<void(int step)>& each = {}) {
  const auto end = std::chrono::steady_clock::now() + duration;
  int step = 0;
  while (std::chrono::steady_clock::now() < end) {
    for (Drone* d : drones) d->Step(step * 0.005, step % 40 == 0);
    if (each) each(step);
    ++step;
    std::this_thread::sleep_for(5ms);
  }
}

// The lines about `peer` after the first window with a pong (discovery straddles that one).
std::vector<LinkLine> AfterFirstContact(const std::vector<LinkLine>& lines, const std::string& peer) {
  std::vector<LinkLine> out;
  bool contact = false;
  for (const LinkLine& l : lines) {
    if (l.peer != peer) continue;
    if (contact) out.push_back(l);
    contact = contact || l.received > 0;
  }
  return out;
}

TEST(DdsRadio, TwoDronesOnLoopbackSeeACleanLinkAndHearEachOther) {
  const std::vector<std::string> members = {"scout_1", "scout_2"};
  Drone a(224, "scout_1", members, members), b(224, "scout_2", members, members);
  ASSERT_TRUE(a.probe && b.probe);
  RunFor({&a, &b}, 6000ms, [&](int step) {
    if (step % 20 != 0) return;
    bus::RadioFrame f;
    f.to = "scout_2";
    bus::RaftMessage m;
    m.to = "scout_2";
    m.payload = {1, 2, 3, static_cast<std::uint8_t>(step / 20)};
    f.raft_msg.push_back(m);
    a.radio->Send(f);
  });
  for (Drone* d : {&a, &b}) {
    const std::string peer = d == &a ? "scout_2" : "scout_1";
    const std::vector<LinkLine> clean = AfterFirstContact(d->lines, peer);
    ASSERT_GE(clean.size(), 2u) << d->name << " never heard " << peer;
    std::uint64_t sent = 0, received = 0;
    for (const LinkLine& l : clean) {
      sent += l.sent;
      received += l.received;
      ASSERT_TRUE(l.has_rtt);
      // Loopback: the pong waits for the peer's next control step (5 ms here), well under 100 ms.
      EXPECT_LT(l.rtt_ms_p50, 100.0) << d->name;
    }
    EXPECT_GE(sent, 40u);
    EXPECT_GE(static_cast<double>(received), 0.98 * static_cast<double>(sent)) << d->name;
    EXPECT_GT(d->states_from[peer], 10) << d->name;
    EXPECT_EQ(d->states_from.count(d->name), 0u) << "own states are not heard";
  }
  ASSERT_GT(b.raft_payloads.size(), 20u);
  EXPECT_EQ(b.raft_payloads.back().size(), 4u);
  EXPECT_TRUE(a.raft_payloads.empty());
  EXPECT_EQ(a.radio->counters().send_errors, 0u);
  EXPECT_EQ(b.radio->counters().inbox_drops, 0u);
}

TEST(DdsRadio, OnlyCountsPongsAddressedToItAndReportsAMissingPeerLost) {
  // a pings b and ghost; c pings b too (b answers both); a must not count c's pongs.
  Drone a(226, "a", {"a", "b", "ghost"}, {"b", "ghost"});
  Drone b(226, "b", {"a", "b", "c"}, {"a"});
  Drone c(226, "c", {"b", "c"}, {"b"});
  ASSERT_TRUE(a.probe && b.probe && c.probe);
  RunFor({&a, &b, &c}, 3000ms);
  std::uint64_t from_b = 0;
  for (const LinkLine& l : a.lines) {
    if (l.peer == "b") from_b += l.received;
    if (l.peer == "ghost") {
      EXPECT_EQ(l.received, 0u);
      EXPECT_EQ(l.loss, 1.0);
    }
  }
  EXPECT_GT(from_b, 0u);
  EXPECT_LE(a.probe->counters().pongs_received, a.probe->counters().pings_sent);
  EXPECT_GT(b.probe->counters().pongs_sent, a.probe->counters().pings_sent / 2);  // b answered a and c
  EXPECT_GT(b.probe->counters().pongs_sent, 0u);
}

TEST(DdsRadio, RefusesBadNamesAndPingsWithoutPeers) {
  auto mesh = Mesh(225);
  ASSERT_TRUE(mesh);
  auto bad_self = DdsRadio::Create(*mesh, "scout-1", {});
  ASSERT_FALSE(bad_self);
  EXPECT_EQ(bad_self.error().code(), ErrorCode::kInvalidArgument);
  auto bad_member = DdsRadio::Create(*mesh, "a", {.members = {"b c"}});
  ASSERT_FALSE(bad_member);
  EXPECT_NE(bad_member.error().ToString().find("member"), std::string::npos);
  auto alone = DdsRadio::Create(*mesh, "a", {.members = {"a"}, .pings = true});
  ASSERT_FALSE(alone);
  EXPECT_NE(alone.error().ToString().find("need another member"), std::string::npos);
  // Without Raft, a raft frame is a send error, not a crash.
  auto plain = DdsRadio::Create(*mesh, "a", {});
  ASSERT_TRUE(plain) << plain.error().ToString();
  bus::RadioFrame f;
  f.raft_msg.emplace_back();
  (*plain)->Send(f);
  EXPECT_EQ((*plain)->counters().send_errors, 1u);
}

TEST(DdsRadio, CarriesBrainMessagesToTheirAddresseesOnly) {
  // Three radios with brains on one mesh: a broadcast reaches the two others, an addressed
  // message only its addressee; nobody hears itself.
  std::vector<std::unique_ptr<bus::Participant>> meshes;
  std::vector<std::unique_ptr<DdsRadio>> radios;
  const std::vector<std::string> names = {"a", "b", "c"};
  for (const std::string& n : names) {
    meshes.push_back(Mesh(226));
    ASSERT_TRUE(meshes.back());
    auto r = DdsRadio::Create(*meshes.back(), n, {.members = {}, .raft = false, .pings = false, .hear_states = false, .brains = true});
    ASSERT_TRUE(r) << r.error().ToString();
    radios.push_back(std::move(*r));
  }
  std::map<std::string, std::vector<std::string>> heard;  // receiver -> "from>to:topic:payload size"
  const auto end = std::chrono::steady_clock::now() + 8s;
  std::vector<bus::RadioFrame> frames;
  while (std::chrono::steady_clock::now() < end) {
    bus::RadioFrame f;
    bus::BrainMessage m;
    m.topic = "rv/vote";
    m.payload = {1, 2, 3};
    f.brain_msg.push_back(m);
    radios[0]->Send(f);  // broadcast
    f.to = "c";
    f.brain_msg[0].topic = "rv/ack";
    f.brain_msg[0].to = "c";
    radios[0]->Send(f);
    for (std::size_t i = 0; i < radios.size(); ++i) {
      frames.clear();
      radios[i]->TakeReceived(bus::SensorSample{}, &frames);
      for (const bus::RadioFrame& r : frames) {
        ASSERT_EQ(r.brain_msg.size(), 1u);
        const bus::BrainMessage& b = r.brain_msg[0];
        EXPECT_EQ(r.from, b.from);
        EXPECT_GT(r.size_bytes, 106u);
        heard[names[i]].push_back(b.from + ">" + b.to + ":" + b.topic + ":" + std::to_string(b.payload.size()));
      }
    }
    const auto has = [&](const std::string& who, const std::string& what) {
      return std::find(heard[who].begin(), heard[who].end(), what) != heard[who].end();
    };
    if (has("b", "a>:rv/vote:3") && has("c", "a>:rv/vote:3") && has("c", "a>c:rv/ack:3")) break;
    std::this_thread::sleep_for(20ms);
  }
  EXPECT_TRUE(heard["a"].empty());
  ASSERT_FALSE(heard["b"].empty());
  for (const std::string& h : heard["b"]) EXPECT_EQ(h, "a>:rv/vote:3");
  EXPECT_NE(std::find(heard["c"].begin(), heard["c"].end(), "a>c:rv/ack:3"), heard["c"].end());
  EXPECT_NE(std::find(heard["c"].begin(), heard["c"].end(), "a>:rv/vote:3"), heard["c"].end());
  EXPECT_EQ(radios[0]->counters().send_errors, 0u);
  // Without brains, a brain frame is a send error.
  auto plain = DdsRadio::Create(*meshes[1], "d", {});
  ASSERT_TRUE(plain) << plain.error().ToString();
  bus::RadioFrame f;
  f.brain_msg.emplace_back();
  (*plain)->Send(f);
  EXPECT_EQ((*plain)->counters().send_errors, 1u);
}

}  // namespace
}  // namespace swarmbox::radio
