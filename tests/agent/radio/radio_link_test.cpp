// RadioLink over real DDS (Cyclone DDS on lo, in one process; integration): two links ping each
// other and report a clean link, a peer that does not exist is reported lost, a third link's
// traffic is not counted by the others, and bad arguments fail loudly. DDS domains 224-226.
#include "swarmbox/radio/radio_link.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <string>
#include <thread>
#include <vector>

namespace swarmbox::radio {
namespace {

using namespace std::chrono_literals;

std::unique_ptr<bus::Participant> Mesh(int domain) {
  auto p = bus::Participant::Create({.backend = "cyclonedds", .domain_id = domain,
                                     .interface = "lo"});
  EXPECT_TRUE(p) << p.error().ToString();
  return p ? std::move(*p) : nullptr;
}

RadioLinkOptions Fast() {
  return RadioLinkOptions{.ping_every = 50ms, .timeout = 500ms, .report_every = 1000ms};
}

// Polls every link every 5 ms for `duration`; returns the parsed link lines by node.
std::map<std::string, std::vector<LinkLine>> PollFor(std::vector<RadioLink*> links,
                                                    std::chrono::milliseconds duration) {
  std::map<std::string, std::vector<LinkLine>> lines;
  const auto end = std::chrono::steady_clock::now() + duration;
  double sim_t = 0.0;
  while (std::chrono::steady_clock::now() < end) {
    for (RadioLink* l : links) {
      for (const LogEvent& e : l->Poll(std::chrono::steady_clock::now(), sim_t)) {
        auto parsed = ParseLinkLine(e.str());
        EXPECT_TRUE(parsed) << e.str();
        if (parsed) lines[parsed->node].push_back(*parsed);
      }
    }
    std::this_thread::sleep_for(5ms);
    sim_t += 0.005;
  }
  return lines;
}

// The lines of `node` about `peer` after discovery: those after the first window with a pong
// (that window straddles the one-sided matching of discovery, where pings are still lost).
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

TEST(RadioLink, TwoDronesOnLoopbackSeeACleanFastLink) {
  auto mesh_a = Mesh(224);
  auto mesh_b = Mesh(224);
  ASSERT_TRUE(mesh_a && mesh_b);
  auto a = RadioLink::Create(*mesh_a, "scout_1", {"scout_1", "scout_2"}, Fast());
  auto b = RadioLink::Create(*mesh_b, "scout_2", {"scout_1", "scout_2"}, Fast());
  ASSERT_TRUE(a) << a.error().ToString();
  ASSERT_TRUE(b) << b.error().ToString();
  EXPECT_EQ((*a)->peers(), std::vector<std::string>{"scout_2"});

  auto lines = PollFor({a->get(), b->get()}, 6000ms);
  for (const auto& [node, peer] : std::vector<std::pair<std::string, std::string>>{
           {"scout_1", "scout_2"}, {"scout_2", "scout_1"}}) {
    const std::vector<LinkLine> clean = AfterFirstContact(lines[node], peer);
    ASSERT_GE(clean.size(), 2u) << node << " never heard " << peer;
    std::uint64_t sent = 0, received = 0;
    for (const LinkLine& l : clean) {
      sent += l.sent;
      received += l.received;
      ASSERT_TRUE(l.has_rtt);
      // Loopback, same process: well under the 500 ms timeout even on a loaded 2-core machine.
      EXPECT_LT(l.rtt_ms_p50, 100.0) << node;
      EXPECT_LE(l.rtt_ms_p50, l.rtt_ms_p99);
    }
    EXPECT_GE(sent, 40u);  // 20 pings/s over >= 2 full windows
    // Nothing is lost on loopback once matched; allow 2 % for a socket buffer overrun when the
    // shared machine stalls a receive thread.
    EXPECT_GE(static_cast<double>(received), 0.98 * static_cast<double>(sent)) << node;
  }
  EXPECT_GT((*a)->counters().pings_answered, 0u);
  EXPECT_GT((*b)->counters().pongs_received, 0u);
}

TEST(RadioLink, APeerThatNeverAnswersIsReportedLost) {
  auto mesh = Mesh(225);
  ASSERT_TRUE(mesh);
  auto a = RadioLink::Create(*mesh, "scout_1", {"ghost"}, Fast());
  ASSERT_TRUE(a) << a.error().ToString();
  auto lines = PollFor({a->get()}, 2600ms);
  ASSERT_FALSE(lines["scout_1"].empty());
  for (const LinkLine& l : lines["scout_1"]) {
    EXPECT_EQ(l.peer, "ghost");
    EXPECT_GT(l.sent, 0u);
    EXPECT_EQ(l.received, 0u);
    EXPECT_EQ(l.loss, 1.0);
    EXPECT_FALSE(l.has_rtt);
  }
}

TEST(RadioLink, OnlyCountsPongsAddressedToItFromItsPeers) {
  auto mesh_a = Mesh(226);
  auto mesh_b = Mesh(226);
  auto mesh_c = Mesh(226);
  ASSERT_TRUE(mesh_a && mesh_b && mesh_c);
  // a pings b only; c pings b too (b answers both); a must not count c's pongs.
  auto a = RadioLink::Create(*mesh_a, "a", {"b"}, Fast());
  auto b = RadioLink::Create(*mesh_b, "b", {"a"}, Fast());
  auto c = RadioLink::Create(*mesh_c, "c", {"b"}, Fast());
  ASSERT_TRUE(a && b && c);
  auto lines = PollFor({a->get(), b->get(), c->get()}, 3000ms);
  std::uint64_t a_received = 0;
  for (const LinkLine& l : lines["a"]) {
    EXPECT_EQ(l.peer, "b");
    a_received += l.received;
  }
  const RadioLink::Counters ca = (*a)->counters();
  EXPECT_GT(a_received, 0u);
  // Every pong a counted came for one of its own pings: no more than it sent.
  EXPECT_LE(ca.pongs_received, ca.pings_sent);
  EXPECT_GT(ca.ignored, 0u);  // it saw c's pings to b and b's pongs to c
  EXPECT_GT((*b)->counters().pings_answered, ca.pings_sent);  // b answered a and c
}

TEST(RadioLink, RefusesBadNamesOptionsAndAnEmptyPeerList) {
  auto mesh = Mesh(225);
  ASSERT_TRUE(mesh);
  auto bad_self = RadioLink::Create(*mesh, "scout-1", {"b"});
  ASSERT_FALSE(bad_self);
  EXPECT_EQ(bad_self.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(bad_self.error().message().find("radio link"), std::string::npos);
  auto bad_peer = RadioLink::Create(*mesh, "a", {"b c"});
  ASSERT_FALSE(bad_peer);
  EXPECT_NE(bad_peer.error().message().find("radio link: peer"), std::string::npos);
  auto alone = RadioLink::Create(*mesh, "a", {"a", "a"});
  ASSERT_FALSE(alone);
  EXPECT_EQ(alone.error().message(), "radio link: no peer to ping besides 'a'");
  auto zero = RadioLink::Create(*mesh, "a", {"b"}, {.ping_every = 0ms});
  ASSERT_FALSE(zero);
  EXPECT_EQ(zero.error().message(),
            "radio link: ping_every, timeout and report_every must be positive (got 0 ms, 1000 ms, "
            "2000 ms)");
}

}  // namespace
}  // namespace swarmbox::radio
