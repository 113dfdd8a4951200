// OffboardFailsafe: each transition of offboard_failsafe.hpp at exact simulated times (steps of
// 1/8 s and 4 ms, as the lockstep gives them), and the log lines the agent prints.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "swarmbox/flight/offboard_failsafe.hpp"

namespace swarmbox::flight {
namespace {

using Action = OffboardFailsafe::Action;
using EventKind = OffboardFailsafe::EventKind;

std::vector<OffboardFailsafe::Event> Drain(OffboardFailsafe& fs) {
  std::vector<OffboardFailsafe::Event> out;
  OffboardFailsafe::Event e;
  while (fs.PopEvent(&e)) out.push_back(e);
  return out;
}

// Steps of 0.125 s (exact in binary) from t0 to t1 inclusive; `answered(t)` per step. Returns the
// time of the first step whose action is `want`, or -1.
template <typename Answered>
double RunUntil(OffboardFailsafe& fs, double t0, double t1, Answered answered, Action want) {
  for (double t = t0; t <= t1; t += 0.125) {
    if (fs.Update(t, answered(t)) == want) return t;
  }
  return -1.0;
}

TEST(OffboardFailsafe, AnsweringStreamNeverTriggers) {
  OffboardFailsafe fs(1.0, 5.0);
  EXPECT_EQ(RunUntil(fs, 0.0, 60.0, [](double) { return true; }, Action::kHold), -1.0);
  EXPECT_EQ(fs.action(), Action::kNone);
  EXPECT_TRUE(Drain(fs).empty());
  EXPECT_EQ(fs.last_answer_s(), 60.0);
}

TEST(OffboardFailsafe, SilenceLongerThanTheTimeoutHolds) {
  // Given a brain answering every step until t = 2, then silent.
  OffboardFailsafe fs(1.0, 5.0);
  const auto answered = [](double t) { return t <= 2.0; };
  // When the stream stops: silence of exactly the timeout (t = 3) is not longer than it.
  EXPECT_EQ(RunUntil(fs, 0.0, 3.0, answered, Action::kHold), -1.0);
  EXPECT_TRUE(Drain(fs).empty());
  // Then the next step (silent 1.125 s) holds, with one event saying so.
  EXPECT_EQ(fs.Update(3.125, false), Action::kHold);
  const auto ev = Drain(fs);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, EventKind::kLost);
  EXPECT_EQ(ev[0].t_s, 3.125);
  EXPECT_EQ(ev[0].silent_s, 1.125);
  EXPECT_EQ(ev[0].action, Action::kHold);
  EXPECT_EQ(OffboardFailsafe::ToLogEvent(ev[0], "scout_1").str(),
            "t=3.125 node=scout_1 event=offboard_lost silent_s=1.125 action=hold");
  // Holding: no more events while the silence lasts less than timeout + hold.
  EXPECT_EQ(RunUntil(fs, 3.25, 8.0, answered, Action::kLand), -1.0);
  EXPECT_EQ(fs.action(), Action::kHold);
  EXPECT_TRUE(Drain(fs).empty());
}

TEST(OffboardFailsafe, HoldSecondsMoreSilenceLands) {
  OffboardFailsafe fs(1.0, 5.0);
  const auto answered = [](double t) { return t <= 2.0; };
  // Silent from t = 2: lost after 1 s (first step past 3.0), land after 1 + 5 s (first step past 8.0).
  EXPECT_EQ(RunUntil(fs, 0.0, 20.0, answered, Action::kLand), 8.125);
  const auto ev = Drain(fs);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].kind, EventKind::kLost);
  EXPECT_EQ(ev[0].t_s, 3.125);
  EXPECT_EQ(ev[1].kind, EventKind::kFailsafe);
  EXPECT_EQ(ev[1].t_s, 8.125);
  EXPECT_EQ(ev[1].silent_s, 6.125);
  EXPECT_EQ(ev[1].action, Action::kLand);
  EXPECT_EQ(OffboardFailsafe::ToLogEvent(ev[1], "scout_1").str(),
            "t=8.125 node=scout_1 event=offboard_failsafe action=land silent_s=6.125");
}

TEST(OffboardFailsafe, AnAnswerDuringHoldRegainsTheBrain) {
  OffboardFailsafe fs(1.0, 5.0);
  // Silent from 2 to 4.5, answering again at 4.5 (during the hold).
  const auto answered = [](double t) { return t <= 2.0 || t >= 4.5; };
  EXPECT_EQ(RunUntil(fs, 0.0, 4.375, answered, Action::kLand), -1.0);
  EXPECT_EQ(fs.action(), Action::kHold);
  EXPECT_EQ(fs.Update(4.5, true), Action::kNone);
  const auto ev = Drain(fs);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].kind, EventKind::kLost);
  EXPECT_EQ(ev[1].kind, EventKind::kRegained);
  EXPECT_EQ(ev[1].t_s, 4.5);
  EXPECT_EQ(ev[1].silent_s, 2.5);  // the silence that ended
  EXPECT_EQ(ev[1].action, Action::kNone);
  EXPECT_EQ(OffboardFailsafe::ToLogEvent(ev[1], "scout_1").str(),
            "t=4.500 node=scout_1 event=offboard_regained silent_s=2.500");
  // The silence counts afresh from the answer: a second loss 1 s after it, not sooner.
  const auto second = [](double t) { return t <= 6.0; };
  EXPECT_EQ(RunUntil(fs, 4.625, 20.0, second, Action::kHold), 7.125);
  const auto ev2 = Drain(fs);
  ASSERT_EQ(ev2.size(), 1u);
  EXPECT_EQ(ev2[0].silent_s, 1.125);
}

TEST(OffboardFailsafe, OnceLandingItStaysLanding) {
  OffboardFailsafe fs(1.0, 5.0);
  const auto answered = [](double t) { return t <= 2.0; };
  ASSERT_EQ(RunUntil(fs, 0.0, 20.0, answered, Action::kLand), 8.125);
  Drain(fs);
  // The brain comes back: PX4 needs a new mode switch to leave the failsafe; here nothing does.
  EXPECT_EQ(RunUntil(fs, 8.25, 30.0, [](double) { return true; }, Action::kNone), -1.0);
  EXPECT_EQ(fs.action(), Action::kLand);
  EXPECT_TRUE(Drain(fs).empty());
}

TEST(OffboardFailsafe, ABrainThatNeverAnswersIsLostFromTheFirstUpdate) {
  OffboardFailsafe fs(1.0, 5.0);
  const auto never = [](double) { return false; };
  EXPECT_EQ(RunUntil(fs, 10.0, 30.0, never, Action::kHold), 11.125);  // silence counted from t = 10
  EXPECT_EQ(RunUntil(fs, 11.25, 30.0, never, Action::kLand), 16.125);
}

TEST(OffboardFailsafe, ALockstepOf4MsTriggersOnTheFirstStepPastTheThreshold) {
  // t_s from integer nanoseconds as the agent gets it: 3.004 - 2.000 is 1.004 s, and a silence
  // of 1.000 s within floating-point noise (k * 0.004) is not past the timeout.
  OffboardFailsafe fs(1.0, 5.0);
  std::int64_t k_hold = -1, k_land = -1;
  for (std::int64_t k = 0; k <= 3000; ++k) {
    const double t = static_cast<double>(k * 4'000'000) * 1e-9;
    const Action a = fs.Update(t, k <= 500);  // last answer at t = 2.000
    if (a == Action::kHold && k_hold < 0) k_hold = k;
    if (a == Action::kLand && k_land < 0) k_land = k;
  }
  EXPECT_EQ(k_hold, 751);   // t = 3.004
  EXPECT_EQ(k_land, 2001);  // t = 8.004
  const auto ev = Drain(fs);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_NEAR(ev[0].silent_s, 1.004, 1e-9);
  EXPECT_NEAR(ev[1].silent_s, 6.004, 1e-9);
}

TEST(OffboardFailsafe, AJumpPastBothThresholdsGivesBothEventsInOrder) {
  OffboardFailsafe fs(1.0, 0.5);
  fs.Update(0.0, true);
  EXPECT_EQ(fs.Update(2.0, false), Action::kLand);
  const auto ev = Drain(fs);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].kind, EventKind::kLost);
  EXPECT_EQ(ev[0].action, Action::kHold);
  EXPECT_EQ(ev[1].kind, EventKind::kFailsafe);
  EXPECT_EQ(ev[1].action, Action::kLand);
  EXPECT_EQ(ev[0].t_s, 2.0);
  EXPECT_EQ(ev[1].silent_s, 2.0);
}

TEST(OffboardFailsafe, NamesOfEventsAndActions) {
  EXPECT_EQ(OffboardFailsafe::EventName(EventKind::kLost), "offboard_lost");
  EXPECT_EQ(OffboardFailsafe::EventName(EventKind::kFailsafe), "offboard_failsafe");
  EXPECT_EQ(OffboardFailsafe::EventName(EventKind::kRegained), "offboard_regained");
  EXPECT_EQ(OffboardFailsafe::ActionName(Action::kNone), "none");
  EXPECT_EQ(OffboardFailsafe::ActionName(Action::kHold), "hold");
  EXPECT_EQ(OffboardFailsafe::ActionName(Action::kLand), "land");
  OffboardFailsafe fs(0.25, 2.0);
  EXPECT_EQ(fs.timeout_s(), 0.25);
  EXPECT_EQ(fs.hold_s(), 2.0);
}

TEST(OffboardFailsafeDeathTest, BadConfigurationAborts) {
  EXPECT_DEATH(OffboardFailsafe(0.0, 5.0), "timeout_s");
  EXPECT_DEATH(OffboardFailsafe(1.0, -1.0), "hold_s");
}

}  // namespace
}  // namespace swarmbox::flight
