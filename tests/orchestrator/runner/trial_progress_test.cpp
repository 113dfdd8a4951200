// TrialProgress: the live progress line as a fold over a SAR trial's log lines: the first ones
// copied from a real run's logs, the later ones (victims, a leader change) in the exact form the
// agents print them (common/logfmt LogEvent; agent/app/README.md), in an order the runner's log
// streams can deliver them.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "swarmbox/runner/start_progress.hpp"
#include "swarmbox/runner/trial_progress.hpp"

namespace swarmbox::runner {
namespace {

// A trials/sar_search.yaml run: three scouts and a lifter; every agent applies the same Raft log,
// so each committed event arrives once per drone.
const std::vector<std::pair<std::string, std::string>> kSarLines = {
    // Copied from a `swarmbox run trials/sar_search.yaml --set physics.rtf=1` run's logs/.
    {"physics", "t=0.000 node=physics event=ready drones=4"},
    {"scout_1", "t=1.608 node=scout_1 event=link peer=scout_2 sent=9 received=6 loss=0.3333 late=0 dup=0 rtt_ms_mean=199.49 rtt_ms_sd=22.55 rtt_ms_p50=185.06 rtt_ms_p99=227.71 rtt_ms_max=227.71"},
    {"scout_2", "t=1.792 node=scout_2 event=leader_elected term=2 leader=scout_2"},
    {"scout_1", "t=1.808 node=scout_1 event=leader_elected term=2 leader=scout_2"},
    {"scout_1", "t=3.020 node=scout_1 event=mission_stage role=scout stage=taking_off"},
    {"physics", "t=10.000 node=physics event=clock rtf=1.00 steps=2500 late=379 lost=0"},
    {"scout_2", "t=16.236 node=scout_2 event=mission_state state=SEARCH index=3"},
    {"scout_1", "t=16.352 node=scout_1 event=mission_state state=SEARCH index=3"},
    {"scout_1", "t=16.432 node=scout_1 event=mission_stage role=scout stage=searching lane=0"},
    {"physics", "t=20.000 node=physics event=clock rtf=1.00 steps=5000 late=663 lost=0"},
    // Later events in the form the agents print them (mission_state_machine.cpp, scout_behaviour.cpp,
    // lifter_sequence.cpp, sar_brain.cpp).
    {"scout_3", "t=41.200 node=scout_3 event=sighting_reported seq=1 x=35.6 y=19.6 confidence=0.91"},
    {"scout_3", "t=46.200 node=scout_3 event=sighting_reported seq=1 x=35.6 y=19.6 confidence=0.91 retry=1"},
    {"scout_2", "t=46.500 node=scout_2 event=victim_confirmed id=1 x=35.600 y=19.600 index=12"},
    {"scout_1", "t=46.500 node=scout_1 event=victim_confirmed id=1 x=35.600 y=19.600 index=12"},
    {"lifter", "t=46.600 node=lifter event=victim_confirmed id=1 x=35.600 y=19.600 index=12"},
    {"scout_2", "t=46.600 node=scout_2 event=mission_state state=RESCUE index=13"},
    {"scout_1", "t=60.000 node=scout_1 event=sighting_reported seq=2 x=-42.9 y=54.6 confidence=0.88"},
    {"scout_2", "t=61.000 node=scout_2 event=victim_confirmed id=2 x=-42.700 y=54.700 index=20"},
    {"lifter", "t=62.000 node=lifter event=mission_stage role=lifter stage=move_to_victim victim=1"},
    // The leader's log reaches the runner late: an older commit must not move the stage back.
    {"scout_1", "t=46.600 node=scout_1 event=mission_state state=RESCUE index=13"},
    {"scout_3", "t=30.000 node=scout_3 event=mission_state state=SEARCH index=3"},
    {"physics", "t=80.000 node=physics event=clock rtf=1.02 steps=20000 late=0 lost=0"},
    {"lifter", "t=95.000 node=lifter event=victim_delivered victim=1"},
    {"scout_2", "t=95.200 node=scout_2 event=victim_status id=1 status=rescued rescuer=lifter index=31"},
    {"scout_1", "t=95.200 node=scout_1 event=victim_status id=1 status=rescued rescuer=lifter index=31"},
    {"scout_2", "t=96.000 node=scout_2 event=victim_status id=2 status=being_rescued rescuer=lifter index=32"},
    // scout_2 is killed; scout_3 wins term 3 (each voter logs it).
    {"scout_3", "t=101.400 node=scout_3 event=leader_elected term=3 leader=scout_3"},
    {"scout_1", "t=101.400 node=scout_1 event=leader_elected term=3 leader=scout_3"},
    {"scout_2", "t=101.000 node=scout_2 event=leader_elected term=2 leader=scout_2"},  // stale
};

TrialProgress Fold(std::size_t n) {
  TrialProgress p;
  for (std::size_t i = 0; i < n && i < kSarLines.size(); ++i) p.OnLine(kSarLines[i].first, kSarLines[i].second);
  return p;
}

TEST(TrialProgress, BeforeAnyMissionEventShowsClocksAndContainersOnly) {
  const TrialProgress p = Fold(2);
  // (a link line only moves the clock)
  EXPECT_EQ(RenderProgress(p, {600, 3.0, 5, 5}), "sim 1.6/600.0s  wall 3.0s  live 5/5");
}

TEST(TrialProgress, LeaderAndStageComeFromTheCommittedEvents) {
  const TrialProgress p = Fold(10);
  EXPECT_EQ(p.leader, "scout_2");
  EXPECT_EQ(p.stage, "SEARCH");
  ASSERT_TRUE(p.rtf.has_value());
  EXPECT_DOUBLE_EQ(*p.rtf, 1.0);
  // A link line moves nothing but the clock.
  EXPECT_DOUBLE_EQ(p.sim_s, 20.0);
  EXPECT_EQ(RenderProgress(p, {600, 21.0, 5, 5}),
            "sim 20.0/600.0s  rtf 1.00  wall 21.0s  stage SEARCH  leader scout_2  live 5/5");
}

TEST(TrialProgress, VictimsAreCountedOnceWhateverTheNumberOfDronesLoggingThem) {
  const TrialProgress p = Fold(kSarLines.size());
  EXPECT_EQ(p.sightings, 2);  // the retry is the same find
  EXPECT_EQ(p.confirmed.size(), 2u);
  EXPECT_EQ(p.rescued.size(), 1u);  // victim 2 is only being rescued
  EXPECT_EQ(p.stage, "RESCUE");     // the late SEARCH (index 3) does not win over index 13
  EXPECT_EQ(p.leader, "scout_3");   // term 3; the stale term-2 line does not take it back
  EXPECT_DOUBLE_EQ(p.sim_s, 101.4);
  EXPECT_EQ(RenderProgress(p, {600, 104.0, 4, 5}),
            "sim 101.4/600.0s  rtf 1.02  wall 104.0s  stage RESCUE  leader scout_3  victims "
            "sighted 2 confirmed 2 rescued 1  live 4/5");
}

TEST(TrialProgress, MissionCompleteIsTheLastStage) {
  TrialProgress p = Fold(kSarLines.size());
  p.OnLine("lifter", "t=180.000 node=lifter event=mission_complete victims=2 rescued=2");
  EXPECT_EQ(p.stage, "COMPLETE");
  p.OnLine("scout_1", "t=180.100 node=scout_1 event=mission_state state=RETURN index=40");
  EXPECT_EQ(p.stage, "COMPLETE");
}

TEST(TrialProgress, IgnoresLinesThatAreNotEvents) {
  TrialProgress p;
  p.OnLine("physics", "plain text from a library");
  p.OnLine("scout_1", "t=abc node=scout_1 event=leader_elected term=x leader=scout_1");
  p.OnLine("scout_1", "t=3.000 node=scout_1 event=victim_confirmed id=seven");
  EXPECT_TRUE(p.leader.empty());
  EXPECT_TRUE(p.confirmed.empty());
  EXPECT_DOUBLE_EQ(p.sim_s, 3.0);
}

}  // namespace
}  // namespace swarmbox::runner

namespace swarmbox::runner {
namespace {

// The physics server's start (physics_server/app/joining.hpp), in the form it prints it.
TEST(TrialProgress, JoiningLinesShowTheStartAndNameTheMissingDrones) {
  TrialProgress p;
  p.OnLine("physics", "t=0.000 node=physics event=ready drones=101");
  EXPECT_EQ(NotJoinedNote(p), std::nullopt);
  p.OnLine("physics", "t=0.000 node=physics event=joining joined=37 expected=101 "
                      "missing=scout_16,scout_40,scout_41,scout_42,scout_43,scout_44,scout_45,scout_46,"
                      "scout_47,scout_48,+54");
  EXPECT_EQ(RenderProgress(p, {600, 8.0, 101, 101}),
            "sim 0.0/600.0s  wall 8.0s  joining 37/101  live 101/101");
  EXPECT_EQ(NotJoinedNote(p),
            "drones that did not join: scout_16,scout_40,scout_41,scout_42,scout_43,scout_44,scout_45,"
            "scout_46,scout_47,scout_48,+54 (joined 37/101)");
  EXPECT_EQ(JoinedLine(p), std::nullopt);
  p.OnLine("physics", "t=0.000 node=physics event=joined joined=101 expected=101 lost=0 wait_s=6.214");
  EXPECT_EQ(NotJoinedNote(p), std::nullopt);
  EXPECT_EQ(JoinedLine(p), "joined 101/101 in 6.2 s");
  EXPECT_EQ(RenderProgress(p, {600, 9.0, 101, 101}), "sim 0.0/600.0s  wall 9.0s  live 101/101");
  // A joining line arriving late (another stream) does not reopen the start.
  p.OnLine("physics", "t=0.000 node=physics event=joining joined=100 expected=101 missing=scout_7");
  EXPECT_EQ(JoinedLine(p), "joined 101/101 in 6.2 s");
}

TEST(TrialProgress, DronesLostAtTheStartAreNamed) {
  TrialProgress p;
  p.OnLine("physics", "t=0.000 node=physics event=joined joined=99 expected=101 lost=2 wait_s=36.020 "
                      "missing=scout_16,scout_40");
  EXPECT_EQ(NotJoinedNote(p),
            "drones that did not join: scout_16,scout_40 (lost at the start, joined 99/101)");
  EXPECT_EQ(JoinedLine(p), "joined 99/101 in 36.0 s; lost at the start: scout_16,scout_40");
}

TEST(StartProgress, CountsWithAtMostALineASecondAndTheTotalTime) {
  StartProgress p(101);
  std::vector<std::string> lines;
  for (int i = 0; i < 101; ++i) {
    if (auto line = p.OnCreated(0.1 + 0.02 * i)) lines.push_back(*line);
  }
  // The first, one a second after it, the last with the time since the run began.
  EXPECT_EQ(lines, (std::vector<std::string>{"created 1/101", "created 51/101", "created 101/101 in 2.1 s"}));
  EXPECT_EQ(p.OnStarted(3.0), "started 1/101");
  EXPECT_EQ(p.OnStarted(3.5), std::nullopt);
  EXPECT_EQ(p.created(), 101u);
  EXPECT_EQ(p.started(), 2u);
  StartProgress one(1);
  EXPECT_EQ(one.OnStarted(0.25), "started 1/1 in 0.2 s");
}

}  // namespace
}  // namespace swarmbox::runner
