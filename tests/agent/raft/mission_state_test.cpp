// The replicated mission state machine: phases, candidates and decisions, determinism, snapshots.
#include "swarmbox/raft/mission_state.hpp"

#include <gtest/gtest.h>

#include <random>

namespace swarmbox::raft {
namespace {

class MissionStateTest : public ::testing::Test {
 protected:
  ApplyResult Do(const MissionCommand& c) { return m_.Apply(++index_, c); }
  MissionState m_;
  std::uint64_t index_ = 0;
};

TEST_F(MissionStateTest, FullMissionWalksThroughEveryPhase) {
  ApplyResult r = Do(StartSearch{});
  ASSERT_TRUE(r.accepted);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, MissionEvent::Kind::kPhase);
  EXPECT_EQ(r.events[0].phase, MissionPhase::kSearch);
  EXPECT_EQ(r.events[0].index, 1u);
  ASSERT_TRUE(Do(AssignSectors{{Sector{"scout_1", 0, 0, 50, 100}, Sector{"scout_2", 50, 0, 100, 100}}})
                  .accepted);
  ASSERT_NE(m_.SectorOf("scout_2"), nullptr);
  EXPECT_EQ(m_.SectorOf("scout_2")->x_min_m, 50);
  r = Do(ReportSighting{"scout_1", 1, 40, 60, 0.95, 40, 50, 30, 20});
  ASSERT_TRUE(r.accepted);
  EXPECT_TRUE(r.events.empty());  // one view: a candidate, not a victim
  ASSERT_EQ(m_.candidates().size(), 1u);
  r = Do(ConfirmSighting{1, 0.99});  // the leader's decision, once a second view came
  ASSERT_TRUE(r.accepted);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, MissionEvent::Kind::kVictimConfirmed);
  EXPECT_EQ(r.events[0].victim.id, 1u);
  ASSERT_TRUE(Do(ConvergeOn{1}).accepted);
  EXPECT_EQ(m_.phase(), MissionPhase::kConverge);
  ASSERT_TRUE(Do(BeginRescue{1, "lifter"}).accepted);
  EXPECT_EQ(m_.phase(), MissionPhase::kRescue);
  EXPECT_EQ(m_.FindVictim(1)->status, VictimStatus::kBeingRescued);
  EXPECT_EQ(m_.FindVictim(1)->rescuer, "lifter");
  ASSERT_TRUE(Do(MarkRescued{1}).accepted);
  EXPECT_EQ(m_.FindVictim(1)->status, VictimStatus::kRescued);
  EXPECT_EQ(m_.phase(), MissionPhase::kSearch);
  ASSERT_TRUE(Do(ReturnHome{}).accepted);
  ASSERT_TRUE(Do(CompleteMission{}).accepted);
  EXPECT_EQ(m_.phase(), MissionPhase::kComplete);
  EXPECT_EQ(m_.applied_index(), 9u);
}

TEST_F(MissionStateTest, InvalidTransitionsAreRejectedWithReason) {
  ApplyResult r = Do(ConvergeOn{1});
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, "cannot converge in phase IDLE");
  Do(StartSearch{});
  r = Do(ConvergeOn{3});
  EXPECT_EQ(r.reason, "no victim 3");
  r = Do(CompleteMission{});
  EXPECT_EQ(r.reason, "cannot complete in phase SEARCH");
  r = Do(AssignSectors{{Sector{"scout_1", 10, 0, 5, 100}}});
  EXPECT_EQ(r.reason, "sector of scout_1 is not a rectangle with min < max");
  EXPECT_TRUE(m_.sectors().empty());
  EXPECT_EQ(m_.phase(), MissionPhase::kSearch);
}

TEST_F(MissionStateTest, SightingsGatherIntoCandidatesAndNoneConfirmsByItself) {
  Do(StartSearch{});
  // However confident, a sighting opens a candidate; it never makes a victim by itself.
  ApplyResult r = Do(ReportSighting{"scout_1", 1, 10, 20, 0.99, 10, 5, 30, 40.0});
  EXPECT_TRUE(r.accepted);
  EXPECT_TRUE(r.events.empty());
  EXPECT_TRUE(m_.victims().empty());
  // Within 5 m: a second view of the same candidate (any drone); beyond: another candidate.
  EXPECT_TRUE(Do(ReportSighting{"scout_2", 1, 14, 20, 0.7, 14, 35, 30, 41.0}).events.empty());
  EXPECT_TRUE(Do(ReportSighting{"scout_2", 2, 30, 20, 0.6, 30, 5, 30, 42.0}).events.empty());
  ASSERT_EQ(m_.candidates().size(), 2u);
  const Candidate& c = m_.candidates()[0];
  EXPECT_EQ(c.id, 1u);
  EXPECT_EQ(c.status, CandidateStatus::kPending);
  ASSERT_EQ(c.views.size(), 2u);
  EXPECT_EQ(c.views[1].reporter, "scout_2");
  EXPECT_DOUBLE_EQ(c.views[1].viewer_y_m, 35);
  EXPECT_DOUBLE_EQ(c.views[1].t_s, 41.0);
  // The position is the confidence-weighted mean of the detections.
  EXPECT_DOUBLE_EQ(c.x_m, (0.99 * 10 + 0.7 * 14) / (0.99 + 0.7));
  // The leader's decision makes the victim, confirmed by every drone that saw it.
  r = Do(ConfirmSighting{1, 0.98});
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, MissionEvent::Kind::kVictimConfirmed);
  EXPECT_EQ(r.events[0].victim.confirmed_by, (std::vector<std::string>{"scout_1", "scout_2"}));
  EXPECT_EQ(m_.FindCandidate(1)->status, CandidateStatus::kConfirmed);
  EXPECT_EQ(m_.FindCandidate(1)->victim_id, 1u);
  EXPECT_DOUBLE_EQ(m_.FindCandidate(1)->belief, 0.98);
  EXPECT_EQ(Do(ConfirmSighting{1, 0.98}).reason, "no undecided candidate 1");
  // A later sighting there is the victim, not a new candidate.
  r = Do(ReportSighting{"scout_3", 1, 13, 21, 0.99});
  EXPECT_TRUE(r.events.empty());
  EXPECT_EQ(m_.candidates().size(), 2u);
  EXPECT_EQ(m_.victims()[0].confirmed_by.size(), 3u);
}

// A candidate's position comes from its closest looks: a 30 m detection of the heap beside the
// person does not pull the drop point off once an 18 m look has found the person.
TEST_F(MissionStateTest, ACandidatesPositionComesFromItsClosestLooks) {
  Do(StartSearch{});
  Do(ReportSighting{"scout_1", 1, 33.8, 15.0, 0.90, 30, 5, 30, 10.0});  // the heap, from 30 m
  EXPECT_DOUBLE_EQ(m_.FindCandidate(1)->x_m, 33.8);
  Do(ReportSighting{"scout_2", 1, 29.0, 15.2, 0.70, 29, 10, 18, 40.0});  // the person, from 18 m
  EXPECT_DOUBLE_EQ(m_.FindCandidate(1)->x_m, 29.0);
  EXPECT_DOUBLE_EQ(m_.FindCandidate(1)->y_m, 15.2);
  // Later search views from 30 m join the evidence but not the position; looks within 1.25 x
  // the lowest height (here 22.5 m) are averaged by confidence.
  Do(ReportSighting{"scout_1", 2, 32.0, 15.0, 0.95, 30, 5, 30, 50.0});
  EXPECT_DOUBLE_EQ(m_.FindCandidate(1)->x_m, 29.0);
  Do(ReportSighting{"scout_3", 1, 30.0, 15.0, 0.80, 30, 10, 22, 60.0});
  EXPECT_DOUBLE_EQ(m_.FindCandidate(1)->x_m, (0.7 * 29.0 + 0.8 * 30.0) / (0.7 + 0.8));
  // A miss is evidence, not a place: it moves nothing.
  Do(ReportMiss{"scout_2", 2, 1, 29, 10, 10, 70.0});
  EXPECT_DOUBLE_EQ(m_.FindCandidate(1)->x_m, (0.7 * 29.0 + 0.8 * 30.0) / (0.7 + 0.8));
  EXPECT_EQ(m_.FindCandidate(1)->views.size(), 5u);
}

// A revisit handed to another drone (the first gone or too slow) counts the abandoned one, so a
// spot nobody reaches runs out of revisits instead of being revisited for ever.
TEST_F(MissionStateTest, ARevisitHandedToAnotherDroneCountsTheAbandonedOne) {
  Do(StartSearch{});
  Do(ReportSighting{"scout_1", 1, 10, 20, 0.9, 10, 10, 30, 5.0});
  ASSERT_TRUE(Do(RequestRevisit{1, "scout_2", 20}).accepted);
  EXPECT_EQ(m_.FindCandidate(1)->revisits, 0u);
  ASSERT_TRUE(Do(RequestRevisit{1, "scout_3", 80}).accepted);
  EXPECT_EQ(m_.FindCandidate(1)->revisit_drone, "scout_3");
  EXPECT_EQ(m_.FindCandidate(1)->revisits, 1u);
  ASSERT_TRUE(Do(ReportMiss{"scout_3", 1, 1, 10.5, 20, 30, 90.0}).accepted);
  EXPECT_EQ(m_.FindCandidate(1)->revisits, 2u);
}

TEST_F(MissionStateTest, ARevisitIsDoneByItsDronesMissAndARejectedCandidateKeepsItsEvidence) {
  Do(StartSearch{});
  Do(ReportSighting{"scout_1", 1, 10, 20, 0.9, 10, 10, 30, 5.0});
  EXPECT_EQ(Do(RequestRevisit{7, "scout_2", 20}).reason, "no pending candidate 7");
  ASSERT_TRUE(Do(RequestRevisit{1, "scout_2", 20}).accepted);
  EXPECT_EQ(m_.FindCandidate(1)->revisit_drone, "scout_2");
  // Another drone's view does not complete scout_2's revisit; scout_2's miss does.
  Do(ReportSighting{"scout_3", 1, 11, 20, 0.6, 11, 30, 30, 21.0});
  EXPECT_EQ(m_.FindCandidate(1)->revisit_drone, "scout_2");
  ASSERT_TRUE(Do(ReportMiss{"scout_2", 1, 1, 10.5, 20, 30, 30.0}).accepted);
  const Candidate* c = m_.FindCandidate(1);
  EXPECT_TRUE(c->revisit_drone.empty());
  EXPECT_EQ(c->revisits, 1u);
  ASSERT_EQ(c->views.size(), 3u);
  EXPECT_FALSE(c->views[2].detected);
  EXPECT_DOUBLE_EQ(c->views[2].viewer_height_m, 30);
  // Misses share the reporter's seq with its sightings.
  EXPECT_EQ(Do(ReportMiss{"scout_2", 1, 1, 10.5, 20, 30, 31.0}).reason,
            "duplicate or out-of-order sighting seq 1 from scout_2");
  EXPECT_EQ(Do(ReportMiss{"scout_2", 2, 9, 10.5, 20, 30, 31.0}).reason, "no undecided candidate 9");
  ASSERT_TRUE(Do(RejectSighting{1, 0.1}).accepted);
  EXPECT_EQ(m_.FindCandidate(1)->status, CandidateStatus::kRejected);
  EXPECT_EQ(Do(RejectSighting{1, 0.1}).reason, "no pending candidate 1");
  // Rejected is not forgotten: new views still join it, and enough of them may confirm it.
  Do(ReportSighting{"scout_4", 1, 10, 21, 0.95, 30, 21, 30, 90.0});
  EXPECT_EQ(m_.FindCandidate(1)->views.size(), 4u);
  EXPECT_EQ(m_.candidates().size(), 1u);
  ASSERT_TRUE(Do(ConfirmSighting{1, 0.96}).accepted);
  EXPECT_EQ(m_.victims().size(), 1u);
}

TEST_F(MissionStateTest, CandidatesAndTheirViewsAreBounded) {
  Do(StartSearch{});
  std::uint64_t seq = 0;
  for (std::size_t k = 0; k < MissionState::kMaxViews; ++k) {
    ASSERT_TRUE(Do(ReportSighting{"a", ++seq, 0, 0, 0.6}).accepted);
  }
  EXPECT_EQ(Do(ReportSighting{"a", ++seq, 0, 0, 0.6}).reason, "candidate 1 holds 24 views");
  Do(RejectSighting{1, 0.1});
  for (std::size_t k = 1; k < MissionState::kMaxCandidates; ++k) {
    ASSERT_TRUE(Do(ReportSighting{"a", ++seq, 20.0 * static_cast<double>(k), 0, 0.6}).accepted);
  }
  ASSERT_EQ(m_.candidates().size(), MissionState::kMaxCandidates);
  // Full: the oldest decided one (the rejected candidate 1) makes room.
  ASSERT_TRUE(Do(ReportSighting{"a", ++seq, -50, -50, 0.6}).accepted);
  EXPECT_EQ(m_.candidates().size(), MissionState::kMaxCandidates);
  EXPECT_EQ(m_.FindCandidate(1), nullptr);
  EXPECT_NE(m_.FindCandidate(MissionState::kMaxCandidates + 1), nullptr);
}

TEST_F(MissionStateTest, LowConfidenceAndDuplicateSightingsAreRejected) {
  Do(StartSearch{});
  EXPECT_EQ(Do(ReportSighting{"scout_1", 1, 0, 0, 0.3}).reason, "sighting confidence below 0.5");
  EXPECT_TRUE(Do(ReportSighting{"scout_1", 1, 0, 0, 0.6}).accepted);
  // A retried proposal that commits twice is applied once.
  EXPECT_EQ(Do(ReportSighting{"scout_1", 1, 0, 0, 0.6}).reason,
            "duplicate or out-of-order sighting seq 1 from scout_1");
  EXPECT_EQ(Do(ReportSighting{"scout_1", 2, 0, 0, 1.5}).reason,
            "sighting with a non-finite position or a confidence outside [0, 1]");
}

TEST_F(MissionStateTest, SnapshotRoundTripsEveryField) {
  Do(StartSearch{});
  Do(AssignSectors{{Sector{"a", 0, 0, 1, 1}}});
  Do(ReportSighting{"a", 1, 5, 5, 0.6, 5, 1, 30, 3.5});
  Do(ReportSighting{"b", 4, 100, 5, 0.95, 90, 5, 28, 4.5});
  Do(ReportSighting{"c", 2, 101, 5, 0.9, 110, 5, 31, 9});
  Do(RequestRevisit{1, "c", 10});
  Do(ReportMiss{"c", 3, 1, 5, 5, 30, 12});
  Do(RejectSighting{1, 0.15});
  Do(ConfirmSighting{2, 0.99});
  Do(ConvergeOn{1});
  Do(BeginRescue{1, "lifter"});
  auto back = MissionState::DecodeSnapshot(m_.EncodeSnapshot());
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(*back, m_);
  // The restored state goes on exactly like the original.
  MissionState copy = *back;
  EXPECT_EQ(copy.Apply(12, MarkRescued{1}).accepted, m_.Apply(12, MarkRescued{1}).accepted);
  EXPECT_EQ(copy, m_);
}

TEST_F(MissionStateTest, CorruptSnapshotIsAnErrorNotACrash) {
  Do(StartSearch{});
  Do(ReportSighting{"a", 1, 5, 5, 0.95});
  const Bytes good = m_.EncodeSnapshot();
  std::mt19937_64 rng(7);
  for (int i = 0; i < 20000; ++i) {
    Bytes b = good;
    b[rng() % b.size()] = static_cast<std::uint8_t>(rng());
    if (i % 2) b.resize(rng() % b.size());
    (void)MissionState::DecodeSnapshot(b);  // must not crash or read out of bounds
  }
  Bytes bad = good;
  bad[0] = 9;
  auto r = MissionState::DecodeSnapshot(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message(), "unsupported snapshot version 9");
}

TEST_F(MissionStateTest, UndecodableCommandIsRejectedDeterministically) {
  const Bytes junk{kCommandVersion, 200, 3};
  ApplyResult r = m_.ApplyEncoded(1, junk);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, "undecodable command: unknown command kind 200");
  EXPECT_EQ(m_.applied_index(), 1u);
}

TEST(MissionCommand, EveryCommandRoundTrips) {
  const std::vector<MissionCommand> all = {
      StartSearch{}, AssignSectors{{Sector{"x", -1, -2, 3, 4}}},
      ReportSighting{"s", 9, 1.25, -3.5, 0.75, 2, -1, 29.5, 61.25}, ConfirmVictim{"ground", 7, 8}, ConvergeOn{3},
      BeginRescue{3, "lifter"}, MarkRescued{3}, ReturnHome{}, CompleteMission{},
      ReportMiss{"s", 10, 4, 1, 2, 30, 70.5}, RequestRevisit{4, "scout_9", 65.0}, ConfirmSighting{4, 0.97},
      RejectSighting{5, 0.12}};
  for (const MissionCommand& c : all) {
    auto back = DecodeCommand(EncodeCommand(c));
    ASSERT_TRUE(back.ok()) << CommandName(c) << ": " << back.error().ToString();
    EXPECT_EQ(*back, c) << CommandName(c);
  }
}

// Two replicas applying the same random command sequence end in the same state (determinism).
TEST(MissionCommand, SameLogSameStateOnEveryReplica) {
  std::mt19937_64 rng(99);
  MissionState a, b;
  for (std::uint64_t i = 1; i <= 2000; ++i) {
    MissionCommand c;
    switch (rng() % 9) {
      case 0: c = StartSearch{}; break;
      case 6: c = ConfirmSighting{static_cast<std::uint32_t>(1 + rng() % 8), 0.97}; break;
      case 7: c = RejectSighting{static_cast<std::uint32_t>(1 + rng() % 8), 0.1}; break;
      case 8:
        c = ReportMiss{"d" + std::to_string(rng() % 3), i, static_cast<std::uint32_t>(1 + rng() % 8), 0, 0, 30,
                       static_cast<double>(i)};
        break;
      case 1: c = ConvergeOn{static_cast<std::uint32_t>(1 + rng() % 4)}; break;
      case 2: c = BeginRescue{static_cast<std::uint32_t>(1 + rng() % 4), "lifter"}; break;
      case 3: c = MarkRescued{static_cast<std::uint32_t>(1 + rng() % 4)}; break;
      default:
        c = ReportSighting{"d" + std::to_string(rng() % 3), i, static_cast<double>(rng() % 50),
                           static_cast<double>(rng() % 50), static_cast<double>(rng() % 100) / 100};
    }
    const Bytes enc = EncodeCommand(c);
    a.ApplyEncoded(i, enc);
    b.Apply(i, *DecodeCommand(enc));
  }
  EXPECT_EQ(a, b);
  EXPECT_FALSE(a.victims().empty());
}

}  // namespace
}  // namespace swarmbox::raft
