// Lockstep bookkeeping with a fake clock (plain integers).
#include "swarmbox/physics/lockstep.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

namespace swarmbox::physics {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TEST(Lockstep, StepCompletesWhenEveryDroneAnswered) {
  Lockstep ls(2, {.timeout_ns = 100 * kMs, .join_timeout_ns = 1000 * kMs});
  ls.BeginStep(0, 0);
  EXPECT_FALSE(ls.StepComplete(1 * kMs));
  EXPECT_EQ(ls.OnCommand(0, 0, 2 * kMs), Lockstep::Answer::kAccepted);
  EXPECT_FALSE(ls.StepComplete(2 * kMs));
  EXPECT_EQ(ls.OnCommand(1, 0, 3 * kMs), Lockstep::Answer::kAccepted);
  EXPECT_TRUE(ls.StepComplete(3 * kMs));
  EXPECT_TRUE(ls.TakeNewlyLost().empty());
}

// A start of many drones: the join timeout counts from the latest first answer, so the third
// drone, joining 2.5 join timeouts after the step began, is still waited for; the fourth, silent
// for a whole join timeout after the last join, is lost.
TEST(Lockstep, JoinTimeoutCountsFromTheLatestJoin) {
  Lockstep ls(4, {.timeout_ns = 100 * kMs, .join_timeout_ns = 1000 * kMs});
  ls.BeginStep(0, 0);
  EXPECT_EQ(ls.NextDeadlineNs(), 1000 * kMs);
  ls.OnCommand(0, 0, 900 * kMs);
  EXPECT_EQ(ls.NextDeadlineNs(), 1900 * kMs);
  EXPECT_FALSE(ls.StepComplete(1500 * kMs));
  ls.OnCommand(1, 0, 1800 * kMs);
  EXPECT_FALSE(ls.StepComplete(2700 * kMs));
  ls.OnCommand(2, 0, 2500 * kMs);
  EXPECT_FALSE(ls.StepComplete(3499 * kMs));
  EXPECT_TRUE(ls.TakeNewlyLost().empty());
  EXPECT_TRUE(ls.StepComplete(3500 * kMs));
  EXPECT_EQ(ls.TakeNewlyLost(), std::vector<std::size_t>{3});
}

TEST(Lockstep, RejectsWrongStepDuplicatesAndUnknownDrones) {
  Lockstep ls(1, {});
  ls.BeginStep(5, 0);
  EXPECT_EQ(ls.OnCommand(0, 4, 0), Lockstep::Answer::kWrongStep);
  EXPECT_EQ(ls.OnCommand(0, 6, 0), Lockstep::Answer::kWrongStep);
  EXPECT_EQ(ls.OnCommand(3, 5, 0), Lockstep::Answer::kUnknownDrone);
  EXPECT_EQ(ls.OnCommand(0, 5, 0), Lockstep::Answer::kAccepted);
  EXPECT_EQ(ls.OnCommand(0, 5, 0), Lockstep::Answer::kDuplicate);
}

TEST(Lockstep, SilentDroneIsLostAfterTheTimeoutAndTheWorldGoesOn) {
  Lockstep ls(2, {.timeout_ns = 100 * kMs, .join_timeout_ns = 1000 * kMs});
  // Both join at step 0.
  ls.BeginStep(0, 0);
  ls.OnCommand(0, 0, 1 * kMs);
  ls.OnCommand(1, 0, 1 * kMs);
  ASSERT_TRUE(ls.StepComplete(1 * kMs));
  // Step 1: drone 1 goes silent.
  ls.BeginStep(1, 10 * kMs);
  ls.OnCommand(0, 1, 11 * kMs);
  EXPECT_FALSE(ls.StepComplete(109 * kMs));
  EXPECT_EQ(ls.NextDeadlineNs(), 110 * kMs);
  EXPECT_TRUE(ls.StepComplete(110 * kMs));
  EXPECT_EQ(ls.TakeNewlyLost(), std::vector<std::size_t>{1});
  EXPECT_TRUE(ls.lost(1));
  EXPECT_EQ(ls.live_count(), 1u);
  // Later steps do not wait for the lost drone.
  ls.BeginStep(2, 120 * kMs);
  ls.OnCommand(0, 2, 121 * kMs);
  EXPECT_TRUE(ls.StepComplete(121 * kMs));
  EXPECT_TRUE(ls.TakeNewlyLost().empty());  // reported once
}

TEST(Lockstep, LostDroneThatAnswersAgainRejoins) {
  Lockstep ls(1, {.timeout_ns = 10 * kMs, .join_timeout_ns = 10 * kMs});
  ls.BeginStep(0, 0);
  EXPECT_TRUE(ls.StepComplete(10 * kMs));
  EXPECT_EQ(ls.TakeNewlyLost(), std::vector<std::size_t>{0});
  ls.BeginStep(1, 20 * kMs);
  EXPECT_EQ(ls.OnCommand(0, 1, 21 * kMs), Lockstep::Answer::kAccepted);
  EXPECT_FALSE(ls.lost(0));
  EXPECT_EQ(ls.TakeRejoined(), std::vector<std::size_t>{0});
  EXPECT_TRUE(ls.StepComplete(21 * kMs));
}

TEST(Lockstep, DronesThatNeverJoinedGetTheLongerJoinTimeout) {
  Lockstep ls(1, {.timeout_ns = 10 * kMs, .join_timeout_ns = 500 * kMs});
  ls.BeginStep(0, 0);
  EXPECT_FALSE(ls.StepComplete(100 * kMs));
  EXPECT_FALSE(ls.joined(0));
  EXPECT_EQ(ls.NextDeadlineNs(), 500 * kMs);
  EXPECT_TRUE(ls.StepComplete(500 * kMs));
  EXPECT_TRUE(ls.lost(0));
}

TEST(Lockstep, TimeoutCountsFromTheLaterOfStepStartAndLastAnswer) {
  Lockstep ls(1, {.timeout_ns = 50 * kMs, .join_timeout_ns = 50 * kMs});
  ls.BeginStep(0, 0);
  ls.OnCommand(0, 0, 5 * kMs);
  ls.BeginStep(1, 30 * kMs);
  EXPECT_EQ(ls.NextDeadlineNs(), 80 * kMs);
  EXPECT_FALSE(ls.StepComplete(79 * kMs));
  EXPECT_TRUE(ls.StepComplete(80 * kMs));
}

// A drone taken out by a process fault is not waited for and not heard; back, it joins again
// with the join timeout.
TEST(Lockstep, OutDroneIsNeitherWaitedForNorHeardAndComesBackJoining) {
  Lockstep ls(2, {.timeout_ns = 100 * kMs, .join_timeout_ns = 1000 * kMs});
  ls.BeginStep(0, 0);
  ls.OnCommand(0, 0, 1 * kMs);
  ls.OnCommand(1, 0, 1 * kMs);
  ASSERT_TRUE(ls.StepComplete(1 * kMs));
  ls.SetOut(1, true);
  ls.BeginStep(1, 10 * kMs);
  EXPECT_EQ(ls.OnCommand(1, 1, 11 * kMs), Lockstep::Answer::kOut);
  EXPECT_FALSE(ls.StepComplete(11 * kMs));
  ls.OnCommand(0, 1, 12 * kMs);
  EXPECT_TRUE(ls.StepComplete(12 * kMs));
  EXPECT_EQ(ls.live_count(), 1u);
  EXPECT_EQ(ls.lost_count(), 0u);
  // Out for far longer than the step timeout: still not lost.
  ls.BeginStep(2, 5000 * kMs);
  ls.OnCommand(0, 2, 5001 * kMs);
  EXPECT_TRUE(ls.StepComplete(5001 * kMs));
  EXPECT_TRUE(ls.TakeNewlyLost().empty());
  // Back: a joining drone, waited for up to the join timeout (not the step timeout).
  ls.SetOut(1, false);
  EXPECT_FALSE(ls.joined(1));
  ls.BeginStep(3, 6000 * kMs);
  ls.OnCommand(0, 3, 6001 * kMs);
  EXPECT_FALSE(ls.StepComplete(6500 * kMs));
  EXPECT_EQ(ls.NextDeadlineNs(), 7000 * kMs);
  EXPECT_EQ(ls.OnCommand(1, 3, 6600 * kMs), Lockstep::Answer::kAccepted);
  EXPECT_TRUE(ls.StepComplete(6600 * kMs));
  EXPECT_TRUE(ls.joined(1));
  EXPECT_EQ(ls.live_count(), 2u);
}

// The server asks StepComplete/NextDeadlineNs/awaited after every answer: they answer from a cache
// kept by OnCommand (no scan per answer), and must stay exact when the earliest deadline's drones
// answer and a later one becomes the earliest.
TEST(Lockstep, AwaitedAndNextDeadlineFollowEachAnswer) {
  Lockstep ls(3, {.timeout_ns = 100 * kMs, .join_timeout_ns = 1000 * kMs});
  ls.BeginStep(0, 0);
  for (std::size_t i = 0; i < 3; ++i) ls.OnCommand(i, 0, 0);
  ASSERT_TRUE(ls.StepComplete(0));
  // Step 1 at 10 ms: drones 0 and 1 were heard at 0 (deadline 110 ms); drone 2 answered step 0
  // late, at 50 ms (deadline 150 ms).
  ls.BeginStep(1, 10 * kMs);
  EXPECT_EQ(ls.awaited(), 3u);
  EXPECT_EQ(ls.NextDeadlineNs(), 110 * kMs);
  ls.OnCommand(0, 1, 20 * kMs);
  EXPECT_EQ(ls.awaited(), 2u);
  EXPECT_EQ(ls.NextDeadlineNs(), 110 * kMs);  // drone 1 still has it
  EXPECT_EQ(ls.OnCommand(0, 1, 21 * kMs), Lockstep::Answer::kDuplicate);
  EXPECT_EQ(ls.awaited(), 2u);
  ls.OnCommand(1, 1, 30 * kMs);
  EXPECT_EQ(ls.awaited(), 1u);
  EXPECT_EQ(ls.NextDeadlineNs(), 110 * kMs);  // drone 2: max(10, 0) + 100
  EXPECT_FALSE(ls.StepComplete(109 * kMs));
  EXPECT_TRUE(ls.StepComplete(110 * kMs));
  EXPECT_EQ(ls.awaited(), 0u);
  EXPECT_EQ(ls.TakeNewlyLost(), std::vector<std::size_t>{2});
  EXPECT_EQ(ls.NextDeadlineNs(), std::numeric_limits<std::int64_t>::max());
}

TEST(Lockstep, NextDeadlineMovesToTheLaterDroneOnceTheEarliestAnswered) {
  Lockstep ls(2, {.timeout_ns = 100 * kMs, .join_timeout_ns = 1000 * kMs});
  ls.BeginStep(0, 0);
  ls.OnCommand(0, 0, 0);
  ASSERT_FALSE(ls.StepComplete(0));  // drone 1 joins late: its first answer at 500 ms
  ls.OnCommand(1, 0, 500 * kMs);
  ASSERT_TRUE(ls.StepComplete(500 * kMs));
  ls.BeginStep(1, 400 * kMs);      // drone 0: max(400, 0) + 100; drone 1: max(400, 500) + 100
  EXPECT_EQ(ls.NextDeadlineNs(), 500 * kMs);
  ls.OnCommand(0, 1, 450 * kMs);
  EXPECT_EQ(ls.NextDeadlineNs(), 600 * kMs);
  EXPECT_FALSE(ls.StepComplete(599 * kMs));
  EXPECT_TRUE(ls.StepComplete(600 * kMs));
  EXPECT_TRUE(ls.lost(1));
}

}  // namespace
}  // namespace swarmbox::physics
