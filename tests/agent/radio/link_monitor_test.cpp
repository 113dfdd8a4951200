// LinkMonitor: the ping schedule, pong matching, the settling rule for windows, late and duplicate
// pongs, and a seeded simulated radio whose every loss and delay the windows must account for
// exactly.
#include "swarmbox/radio/link_monitor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <utility>
#include <vector>

namespace swarmbox::radio {
namespace {

using namespace std::chrono_literals;

const TimePoint kStart = TimePoint(std::chrono::seconds(1000));

LinkMonitorOptions Opts(std::chrono::milliseconds ping, std::chrono::milliseconds timeout,
                        std::chrono::milliseconds report) {
  return LinkMonitorOptions{.ping_every = ping, .timeout = timeout, .report_every = report};
}

TEST(NearestRankPercentile, FollowsTheNearestRankDefinition) {
  const std::vector<double> v = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  EXPECT_EQ(NearestRankPercentile(v, 0.5), 5);     // ceil(5) = 5th
  EXPECT_EQ(NearestRankPercentile(v, 0.51), 6);    // ceil(5.1) = 6th
  EXPECT_EQ(NearestRankPercentile(v, 0.99), 10);
  EXPECT_EQ(NearestRankPercentile(v, 1.0), 10);
  EXPECT_EQ(NearestRankPercentile({42.0}, 0.5), 42.0);
}

TEST(SummariseRtt, MeanSdPercentilesMaxOfUnsortedSamples) {
  const RttSummary s = SummariseRtt({4.0, 2.0, 8.0, 6.0});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.mean_ms, 5.0);
  EXPECT_DOUBLE_EQ(s.sd_ms, std::sqrt(20.0 / 3.0));  // sample sd
  EXPECT_DOUBLE_EQ(s.p50_ms, 4.0);
  EXPECT_DOUBLE_EQ(s.p99_ms, 8.0);
  EXPECT_DOUBLE_EQ(s.max_ms, 8.0);
  const RttSummary empty = SummariseRtt({});
  EXPECT_EQ(empty.count, 0u);
  EXPECT_EQ(empty.mean_ms, 0.0);
}

TEST(LinkMonitor, PingsEveryPeerOncePerPeriodWithoutBursts) {
  LinkMonitor m({"b", "c"}, Opts(200ms, 1000ms, 2000ms), kStart);
  std::vector<PingToSend> out;
  m.DuePings(kStart, out);
  EXPECT_EQ(out, (std::vector<PingToSend>{{0, 1}, {1, 1}}));
  out.clear();
  m.DuePings(kStart + 199ms, out);
  EXPECT_TRUE(out.empty());
  m.DuePings(kStart + 200ms, out);
  EXPECT_EQ(out, (std::vector<PingToSend>{{0, 2}, {1, 2}}));
  out.clear();
  // Polled 1 s late: one round now, the next one period later (no catch-up burst).
  m.DuePings(kStart + 1400ms, out);
  EXPECT_EQ(out, (std::vector<PingToSend>{{0, 3}, {1, 3}}));
  out.clear();
  m.DuePings(kStart + 1599ms, out);
  EXPECT_TRUE(out.empty());
  m.DuePings(kStart + 1600ms, out);
  EXPECT_EQ(out.size(), 2u);
}

// Names of the pings in `out` (peers() is sorted by name).
std::vector<std::string> Pinged(const LinkMonitor& m, const std::vector<PingToSend>& out) {
  std::vector<std::string> names;
  for (const PingToSend& p : out) names.push_back(m.peers()[p.peer]);
  return names;
}

TEST(LinkMonitor, KeepsPeersSortedByName) {
  LinkMonitor m({"scout_2", "lifter", "scout_10", "scout_1"}, Opts(200ms, 1000ms, 2000ms), kStart);
  EXPECT_EQ(m.peers(), (std::vector<std::string>{"lifter", "scout_1", "scout_10", "scout_2"}));
  std::vector<PingToSend> out;
  m.DuePings(kStart, out);  // ping_peers 0: every peer, in that order
  EXPECT_EQ(Pinged(m, out), m.peers());
}

TEST(LinkMonitor, SamplesPingPeersPerRoundRoundRobinHeardFirst) {
  // Given six peers, two pings per round, and c, e heard within the last 5 s, a heard long ago.
  LinkMonitorOptions o = Opts(200ms, 1000ms, 2000ms);
  o.ping_peers = 2;
  LinkMonitor m({"f", "e", "d", "c", "b", "a"}, o, kStart);
  m.Heard("a", kStart - 6s);
  m.Heard("c", kStart - 1s);
  m.Heard("e", kStart - 3500ms);
  m.Heard("stranger", kStart);  // not a peer: ignored
  // Then one cycle is the heard peers by name, then the others by name, two per round.
  std::vector<std::string> order;
  for (int round = 0; round < 6; ++round) {
    std::vector<PingToSend> out;
    m.DuePings(kStart + round * 200ms, out);
    ASSERT_EQ(out.size(), 2u) << round;
    for (const std::string& n : Pinged(m, out)) order.push_back(n);
  }
  // Round 0: c, e (heard); 1: a, b (a silent 6 s: the others' pass); 2: d, f; then again (at
  // kStart + 1 s e was heard 4.5 s ago: still recent).
  EXPECT_EQ(order, (std::vector<std::string>{"c", "e", "a", "b", "d", "f", "c", "e", "a", "b", "d", "f"}));
  // Every peer's seq counts only its own pings.
  std::vector<PingToSend> out;
  m.DuePings(kStart + 1600ms, out);
  EXPECT_EQ(out, (std::vector<PingToSend>{{2, 3}, {0, 3}}));  // e has aged out (5.1 s): c, then a
}

TEST(LinkMonitor, SamplingTakesNoPeerTwiceInARound) {
  // Fewer peers in the cycle's remainder than ping_peers: the round wraps into the next pass
  // without repeating a peer, and never sends more pings than peers.
  LinkMonitorOptions o = Opts(100ms, 1000ms, 2000ms);
  o.ping_peers = 2;
  LinkMonitor m({"a", "b", "c"}, o, kStart);
  m.Heard("b", kStart);
  std::size_t pings = 0;
  for (int round = 0; round < 30; ++round) {
    std::vector<PingToSend> out;
    m.DuePings(kStart + round * 100ms, out);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_NE(out[0].peer, out[1].peer) << round;
    pings += out.size();
  }
  EXPECT_EQ(pings, 60u);
}

TEST(LinkMonitor, PingPeersAtLeastThePeerCountPingsEveryPeerEveryRound) {
  LinkMonitorOptions o = Opts(200ms, 1000ms, 2000ms);
  o.ping_peers = 3;
  LinkMonitor m({"c", "b", "d"}, o, kStart);
  std::vector<PingToSend> out;
  m.DuePings(kStart, out);
  EXPECT_EQ(out, (std::vector<PingToSend>{{0, 1}, {1, 1}, {2, 1}}));
}

TEST(LinkMonitor, MatchesPongsBySeqAndReportsRtt) {
  LinkMonitor m({"b"}, Opts(100ms, 1000ms, 1000ms), kStart);
  std::vector<PingToSend> out;
  m.DuePings(kStart, out);           // seq 1 at 0 ms
  m.DuePings(kStart + 100ms, out);   // seq 2 at 100 ms
  // Out of order: seq 2 first.
  EXPECT_EQ(m.OnPong("b", 2, kStart + 130ms), PongResult::kMatched);  // 30 ms
  EXPECT_EQ(m.OnPong("b", 1, kStart + 50ms), PongResult::kMatched);   // 50 ms
  EXPECT_FALSE(m.TakeReport(kStart + 999ms));
  auto r = m.TakeReport(kStart + 1000ms);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->size(), 1u);
  const LinkWindow& w = (*r)[0];
  EXPECT_EQ(w.peer, "b");
  EXPECT_EQ(w.sent, 2u);
  EXPECT_EQ(w.received, 2u);
  EXPECT_EQ(w.loss(), 0.0);
  EXPECT_DOUBLE_EQ(w.rtt.mean_ms, 40.0);
  EXPECT_DOUBLE_EQ(w.rtt.p50_ms, 30.0);
  EXPECT_DOUBLE_EQ(w.rtt.p99_ms, 50.0);
}

TEST(LinkMonitor, PendingPingsCarryIntoTheNextWindowAndTimeoutsCountAsLost) {
  LinkMonitor m({"b"}, Opts(500ms, 1000ms, 1000ms), kStart);
  std::vector<PingToSend> out;
  m.DuePings(kStart, out);           // seq 1
  m.DuePings(kStart + 500ms, out);   // seq 2
  // Window 1 ends at 1000 ms: seq 1 has just timed out (sent 1000 ms ago), seq 2 is still pending.
  auto r1 = m.TakeReport(kStart + 1000ms);
  ASSERT_TRUE(r1);
  EXPECT_EQ((*r1)[0].sent, 1u);
  EXPECT_EQ((*r1)[0].received, 0u);
  EXPECT_EQ((*r1)[0].loss(), 1.0);
  EXPECT_EQ((*r1)[0].rtt.count, 0u);
  // seq 2's pong arrives in window 2 (900 ms RTT, under the timeout): counted there.
  EXPECT_EQ(m.OnPong("b", 2, kStart + 1400ms), PongResult::kMatched);
  auto r2 = m.TakeReport(kStart + 2000ms);
  ASSERT_TRUE(r2);
  EXPECT_EQ((*r2)[0].sent, 1u);
  EXPECT_EQ((*r2)[0].received, 1u);
  EXPECT_DOUBLE_EQ((*r2)[0].rtt.mean_ms, 900.0);
}

TEST(LinkMonitor, LateAndDuplicatePongsChangeNeitherCountsNorRtt) {
  LinkMonitor m({"b"}, Opts(100ms, 300ms, 1000ms), kStart);
  std::vector<PingToSend> out;
  m.DuePings(kStart, out);          // seq 1
  m.DuePings(kStart + 100ms, out);  // seq 2
  EXPECT_EQ(m.OnPong("b", 1, kStart + 20ms), PongResult::kMatched);
  EXPECT_EQ(m.OnPong("b", 1, kStart + 25ms), PongResult::kDuplicate);
  // seq 2 answered exactly at its timeout: lost (a pong older than the timeout is lost).
  EXPECT_EQ(m.OnPong("b", 2, kStart + 400ms), PongResult::kLate);
  EXPECT_EQ(m.OnPong("b", 2, kStart + 450ms), PongResult::kLate);
  auto r = m.TakeReport(kStart + 1000ms);
  ASSERT_TRUE(r);
  const LinkWindow& w = (*r)[0];
  EXPECT_EQ(w.sent, 2u);
  EXPECT_EQ(w.received, 1u);
  EXPECT_EQ(w.late, 2u);
  EXPECT_EQ(w.duplicates, 1u);
  EXPECT_DOUBLE_EQ(w.loss(), 0.5);
  EXPECT_EQ(w.rtt.count, 1u);
  EXPECT_DOUBLE_EQ(w.rtt.mean_ms, 20.0);
}

TEST(LinkMonitor, PongsLongAfterTheirPingWereForgottenCountAsLate) {
  LinkMonitor m({"b"}, Opts(100ms, 200ms, 1000ms), kStart);
  std::vector<PingToSend> out;
  m.DuePings(kStart, out);  // seq 1, lost
  for (int i = 1; i <= 20; ++i) m.DuePings(kStart + i * 100ms, out);  // forgets seq 1 after 800 ms
  EXPECT_EQ(m.OnPong("b", 1, kStart + 2050ms), PongResult::kLate);
}

TEST(LinkMonitor, RefusesPongsFromStrangersAndForSeqsNeverSent) {
  LinkMonitor m({"b"}, Opts(100ms, 1000ms, 1000ms), kStart);
  std::vector<PingToSend> out;
  m.DuePings(kStart, out);
  EXPECT_EQ(m.OnPong("z", 1, kStart + 1ms), PongResult::kUnknownPeer);
  EXPECT_EQ(m.OnPong("b", 0, kStart + 1ms), PongResult::kUnknownSeq);
  EXPECT_EQ(m.OnPong("b", 2, kStart + 1ms), PongResult::kUnknownSeq);
  EXPECT_EQ(m.refused(), 3u);
  auto r = m.TakeReport(kStart + 1000ms);
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)[0].sent, 1u);  // seq 1 timed out
  EXPECT_EQ((*r)[0].received, 0u);
}

TEST(LinkMonitor, PeersWithNothingSettledStillGetAnEmptyWindow) {
  LinkMonitor m({"b", "c"}, Opts(100ms, 5000ms, 1000ms), kStart);
  std::vector<PingToSend> out;
  m.DuePings(kStart, out);
  EXPECT_EQ(m.OnPong("b", 1, kStart + 10ms), PongResult::kMatched);
  auto r = m.TakeReport(kStart + 1000ms);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->size(), 2u);
  EXPECT_EQ((*r)[0].sent, 1u);
  EXPECT_EQ((*r)[1].peer, "c");
  EXPECT_EQ((*r)[1].sent, 0u);  // pending, under the 5 s timeout
  EXPECT_EQ((*r)[1].loss(), 0.0);
}

// A seeded radio: each ping and each pong is lost with probability p and delayed by
// N(mean, sd) one way. Over 30 s with 3 peers, the windows must add up to exactly what the
// simulation did: every ping counted once, the answered ones with their exact RTTs.
TEST(LinkMonitor, WindowsAccountForEverySimulatedPingExactly) {
  const std::vector<std::string> peers = {"b", "c", "d"};
  LinkMonitor m(peers, Opts(200ms, 1000ms, 2000ms), kStart);
  std::mt19937_64 rng(20261121);
  std::normal_distribution<double> one_way_ms(100.0, 20.0);
  std::bernoulli_distribution lost(0.05);

  struct Arrival {
    std::size_t peer;
    std::uint64_t seq;
  };
  std::multimap<TimePoint, Arrival> pongs;  // pongs in flight, by arrival time
  std::map<std::size_t, std::uint64_t> truth_sent, truth_answered;
  std::vector<double> truth_rtt_ms;
  std::uint64_t truth_late = 0;

  std::uint64_t sent = 0, received = 0, late = 0;
  double rtt_sum = 0.0;
  std::vector<PingToSend> due;
  const auto end = kStart + 30s;
  for (auto now = kStart; now <= end + 2s; now += 1ms) {
    // Deliver the pongs that arrive by `now`, in arrival order.
    while (!pongs.empty() && pongs.begin()->first <= now) {
      const auto [at, a] = *pongs.begin();
      pongs.erase(pongs.begin());
      const PongResult r = m.OnPong(peers[a.peer], a.seq, at);
      ASSERT_TRUE(r == PongResult::kMatched || r == PongResult::kLate);
    }
    if (now <= end) {
      due.clear();
      m.DuePings(now, due);
      for (const PingToSend& p : due) {
        ++truth_sent[p.peer];
        if (lost(rng) || lost(rng)) {  // the ping, or its pong
          continue;
        }
        const double rtt = std::max(0.0, one_way_ms(rng)) + std::max(0.0, one_way_ms(rng));
        const auto at = now + std::chrono::microseconds(static_cast<long>(rtt * 1000.0));
        pongs.emplace(at, Arrival{p.peer, p.seq});
        // Within the timeout it is answered; the monitor measures RTT from the ms grid of `now`.
        if (rtt < 1000.0) {
          ++truth_answered[p.peer];
          truth_rtt_ms.push_back(std::chrono::duration<double, std::milli>(at - now).count());
        } else {
          ++truth_late;
        }
      }
    }
    if (auto r = m.TakeReport(now)) {
      for (const LinkWindow& w : *r) {
        sent += w.sent;
        received += w.received;
        late += w.late;
        rtt_sum += w.rtt.mean_ms * static_cast<double>(w.rtt.count);
        EXPECT_EQ(w.rtt.count, w.received);
      }
    }
  }
  std::uint64_t want_sent = 0, want_answered = 0;
  for (const auto& [peer, n] : truth_sent) want_sent += n;
  for (const auto& [peer, n] : truth_answered) want_answered += n;
  double want_rtt_sum = 0.0;
  for (double v : truth_rtt_ms) want_rtt_sum += v;
  EXPECT_EQ(want_sent, 3u * 151u);  // 30 s / 200 ms + 1 rounds, 3 peers
  EXPECT_EQ(sent, want_sent);
  EXPECT_EQ(received, want_answered);
  EXPECT_EQ(late, truth_late);
  EXPECT_NEAR(rtt_sum, want_rtt_sum, 1e-6 * want_rtt_sum);
  // And the figures are those of the simulated radio: loss 1 - 0.95^2, RTT mean 200 ms.
  const double loss = 1.0 - static_cast<double>(received) / static_cast<double>(sent);
  EXPECT_NEAR(loss, 1.0 - 0.95 * 0.95, 0.035);  // 2.5 sigma of a binomial over 453 pings
  EXPECT_NEAR(rtt_sum / static_cast<double>(received), 200.0, 4.0);  // 2.5 x 28.3 / sqrt(~410)
}

}  // namespace
}  // namespace swarmbox::radio
