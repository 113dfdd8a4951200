// Uncertain detections (issue #19.4), step by step on simulated time: the log-odds fusion of
// independent views (sighting_fusion.hpp), the leader's decisions and revisits from the committed
// candidates (leader_planner.hpp), and a scout's revisit that sees nothing (scout_behaviour.hpp).
// Sequences of sightings as data: false alarms, misses, repeated views from the same place.
#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "swarmbox/swarm/leader_planner.hpp"
#include "swarmbox/swarm/scout_behaviour.hpp"
#include "swarmbox/swarm/sighting_fusion.hpp"

namespace swarmbox::swarm {
namespace {

using Eigen::Vector3d;
using raft::Candidate;
using raft::SightingView;

// A detection by `who` at (x, y) seen from (vx, vy) at 30 m, time t.
SightingView Seen(const std::string& who, double c, double vx, double vy, double t, double x = 0, double y = 0) {
  return SightingView{who, 1, x, y, c, vx, vy, 30.0, t, true};
}
// A miss by `who` looking from (vx, vy) at height h, time t.
SightingView Missed(const std::string& who, double vx, double vy, double t, double h = 30.0) {
  return SightingView{who, 1, 0, 0, 0.0, vx, vy, h, t, false};
}
Candidate With(std::vector<SightingView> views) {
  Candidate c;
  c.id = 1;
  c.views = std::move(views);
  return c;
}
double Logit(double p) { return std::log(p / (1 - p)); }

TEST(SightingFusion, OneViewNeverConfirmsHoweverConfident) {
  const FusionParams p;
  for (const double c : {0.6, 0.9, 0.99, 1.0}) {
    const FusionAssessment a = AssessCandidate(With({Seen("scout_1", c, 0, 0, 10)}), p);
    EXPECT_EQ(a.decision, FusionDecision::kNone) << c;
    EXPECT_EQ(a.counted_detections, 1);
    // Prior 0.5: one view's belief is its confidence, capped at max_view_confidence.
    EXPECT_NEAR(a.belief, std::min(c, p.max_view_confidence), 1e-9) << c;
  }
}

TEST(SightingFusion, TwoIndependentViewsFuseByAddingLogOdds) {
  const FusionParams p;
  // Another drone, 20 m away: independent. L = logit(0.9) + logit(0.8).
  FusionAssessment a = AssessCandidate(With({Seen("scout_1", 0.9, 0, 0, 10), Seen("scout_2", 0.8, 20, 0, 11)}), p);
  EXPECT_EQ(a.counted_detections, 2);
  EXPECT_NEAR(a.log_odds, Logit(0.9) + Logit(0.8), 1e-9);
  EXPECT_NEAR(a.belief, 0.972972972972973, 1e-9);  // 36:1
  EXPECT_EQ(a.decision, FusionDecision::kConfirm);
  // Two weak views are not enough: 0.6 and 0.7 fuse to 0.778 < 0.95.
  a = AssessCandidate(With({Seen("scout_1", 0.6, 0, 0, 10), Seen("scout_2", 0.7, 20, 0, 11)}), p);
  EXPECT_NEAR(a.belief, 0.6 * 0.7 / (0.6 * 0.7 + 0.4 * 0.3), 1e-9);
  EXPECT_EQ(a.decision, FusionDecision::kNone);
}

TEST(SightingFusion, ViewsFromNearlyTheSamePlaceAndTimeCountOnce) {
  const FusionParams p;  // 10 m, 10 s
  // The same drone 4 m further along 0.5 s later: the same image, counted once.
  FusionAssessment a = AssessCandidate(With({Seen("scout_1", 0.95, 0, 0, 10), Seen("scout_1", 0.95, 4, 0, 10.5)}), p);
  EXPECT_EQ(a.detections, 2);
  EXPECT_EQ(a.counted_detections, 1);
  EXPECT_EQ(a.decision, FusionDecision::kNone);
  // Two drones flying together (3 m apart) are no second view either.
  a = AssessCandidate(With({Seen("scout_1", 0.95, 0, 0, 10), Seen("scout_2", 0.95, 0, 3, 10)}), p);
  EXPECT_EQ(a.counted_detections, 1);
  // The same drone 10.5 m on (a baseline), or back at the same spot 12 s later (another pass).
  a = AssessCandidate(With({Seen("scout_1", 0.95, 0, 0, 10), Seen("scout_1", 0.95, 10.5, 0, 11.5)}), p);
  EXPECT_EQ(a.counted_detections, 2);
  EXPECT_EQ(a.decision, FusionDecision::kConfirm);
  a = AssessCandidate(With({Seen("scout_1", 0.95, 0, 0, 10), Seen("scout_1", 0.95, 1, 0, 22)}), p);
  EXPECT_EQ(a.counted_detections, 2);
}

TEST(SightingFusion, ARevisitThatSeesNothingLowersTheBeliefUntilRejected) {
  const FusionParams p;
  const double miss = std::log((1 - p.detector_recall) / (1 - p.false_repeat));
  // A transient false alarm at 0.9, then misses on three revisits, 20 s apart, from overhead.
  std::vector<SightingView> v = {Seen("scout_1", 0.9, 10, 0, 10)};
  v.push_back(Missed("scout_2", 0.5, 0, 30));
  FusionAssessment a = AssessCandidate(With(v), p);
  EXPECT_NEAR(a.log_odds, Logit(0.9) + miss, 1e-9);
  EXPECT_EQ(a.counted_misses, 1);
  EXPECT_EQ(a.decision, FusionDecision::kNone);  // 0.66: one look is not enough
  v.push_back(Missed("scout_3", 0.0, 1, 50));
  a = AssessCandidate(With(v), p);
  EXPECT_NEAR(a.belief, 1 / (1 + std::exp(-(Logit(0.9) + 2 * miss))), 1e-9);
  EXPECT_EQ(a.decision, FusionDecision::kNone);  // 0.29 > 0.2
  v.push_back(Missed("scout_2", 1.0, 0, 70));
  a = AssessCandidate(With(v), p);
  EXPECT_LT(a.belief, p.reject_belief);  // 0.08
  EXPECT_EQ(a.decision, FusionDecision::kReject);
  EXPECT_FALSE(a.undecided);
}

TEST(SightingFusion, AMissCountsOnlyWithThePlaceInViewAtAdequateAltitude) {
  const FusionParams p;
  const SightingView first = Seen("scout_1", 0.9, 10, 0, 10);
  for (const SightingView& m : {Missed("scout_2", 8, 0, 30),          // 8 m off the nadir
                                Missed("scout_2", 0, 0, 30, 60.0),     // too high to resolve a person
                                Missed("scout_2", 0, 0, 30, 4.0)}) {   // too low: a sliver of ground
    const FusionAssessment a = AssessCandidate(With({first, m}), p);
    EXPECT_EQ(a.misses, 1);
    EXPECT_EQ(a.counted_misses, 0);
    EXPECT_NEAR(a.belief, 0.9, 1e-9);
  }
}

TEST(SightingFusion, AMissedTrueVictimIsStillConfirmedWhenTheNextLookSeesIt) {
  // A real person: first seen at 0.9, missed once (recall < 1), then seen on the next revisit.
  const FusionParams p;
  const FusionAssessment a = AssessCandidate(
      With({Seen("scout_1", 0.9, 10, 0, 10), Missed("scout_2", 0, 0, 30), Seen("scout_2", 0.95, 0, 0, 50)}), p);
  EXPECT_EQ(a.counted_detections, 2);
  EXPECT_EQ(a.counted_misses, 1);
  EXPECT_NEAR(a.belief, 1 / (1 + std::exp(-(Logit(0.9) + Logit(0.95) + std::log(0.15 / 0.7)))), 1e-9);
  EXPECT_EQ(a.decision, FusionDecision::kConfirm);  // 0.974
}

TEST(SightingFusion, RevisitsRunOutOnAnUndecidedCandidate) {
  const FusionParams p;
  Candidate c = With({Seen("scout_1", 0.7, 10, 0, 10)});
  c.revisits = static_cast<std::uint32_t>(p.max_revisits);
  FusionAssessment a = AssessCandidate(c, p);
  EXPECT_EQ(a.decision, FusionDecision::kReject);
  EXPECT_TRUE(a.undecided);
  c.revisit_drone = "scout_2";  // one more under way: wait for it
  EXPECT_EQ(AssessCandidate(c, p).decision, FusionDecision::kNone);
}

// A close look by `who` from (vx, vy) at the revisit's 18 m, time t.
SightingView CloseSeen(const std::string& who, double c, double vx, double vy, double t) {
  return SightingView{who, 1, 0, 0, c, vx, vy, 18.0, t, true};
}
FusionParams WithCloseLooks() {
  FusionParams p;
  p.close_look_height_m = 21.0;
  return p;
}

// Close looks: many confident views from the search altitude (a look-alike fires on each) raise
// a candidate to 9:1 at most; only a view from the look altitude confirms.
TEST(SightingFusion, WithCloseLooksOnlyACloseLookConfirms) {
  const FusionParams p = WithCloseLooks();
  std::vector<SightingView> v;
  for (int i = 0; i < 5; ++i) v.push_back(Seen("scout_1", 0.9, 12.0 * i, 0, 10.0 + 15 * i));  // 5 passes
  FusionAssessment a = AssessCandidate(With(v), p);
  EXPECT_EQ(a.counted_detections, 5);
  EXPECT_NEAR(a.log_odds, p.max_search_log_odds, 1e-9);
  EXPECT_EQ(a.decision, FusionDecision::kNone);
  EXPECT_EQ(AssessCandidate(With(v), FusionParams{}).decision,
            FusionDecision::kConfirm);                  // without: confirmed
  v.push_back(CloseSeen("scout_2", 0.9, 0.5, 0, 100));  // 9:1 and 9:1 fuse to 81:1
  a = AssessCandidate(With(v), p);
  EXPECT_EQ(a.close_detections, 1);
  EXPECT_NEAR(a.log_odds, p.max_search_log_odds + Logit(0.9), 1e-9);
  EXPECT_EQ(a.decision, FusionDecision::kConfirm);
  // A close look's confidence is capped at max_close_view_confidence, not the search views' cap.
  v.back().confidence = 0.999;
  EXPECT_NEAR(AssessCandidate(With(v), p).log_odds,
              p.max_search_log_odds + Logit(p.max_close_view_confidence), 1e-9);
}

// Weak close looks at a look-alike do not add up: the best close detection counts alone.
TEST(SightingFusion, OnlyTheBestCloseLookCounts) {
  const FusionParams p = WithCloseLooks();
  std::vector<SightingView> v = {Seen("scout_1", 0.8, 0, 0, 10), Seen("scout_1", 0.8, 12, 0, 25)};
  for (int i = 0; i < 3; ++i) v.push_back(CloseSeen("scout_2", 0.6, 0.5, 0, 100.0 + 20 * i));
  FusionAssessment a = AssessCandidate(With(v), p);
  EXPECT_EQ(a.close_detections, 3);
  EXPECT_NEAR(a.log_odds, p.max_search_log_odds + Logit(0.6), 1e-9);
  EXPECT_EQ(a.decision, FusionDecision::kNone);  // 0.93: undecided, rejected once revisits run out
  // A person missed on the first close look and seen on the second: the detection counts, not the miss.
  v.resize(2);
  v.push_back(Missed("scout_2", 0.5, 0, 100, 18.0));
  v.push_back(CloseSeen("scout_3", 0.9, 0.5, 0, 130));
  a = AssessCandidate(With(v), p);
  EXPECT_NEAR(a.log_odds, p.max_search_log_odds + Logit(0.9), 1e-9);
  EXPECT_EQ(a.decision, FusionDecision::kConfirm);
}

TEST(SightingFusion, TwoCloseLooksThatSeeNothingRejectWhatTheSearchViewsRaised) {
  const FusionParams p = WithCloseLooks();
  const double miss = std::log((1 - p.close_recall) / (1 - p.close_false_repeat));
  std::vector<SightingView> v;
  for (int i = 0; i < 4; ++i) v.push_back(Seen("scout_1", 0.85, 12.0 * i, 0, 10.0 + 15 * i));
  v.push_back(Missed("scout_2", 0.5, 0, 100, 18.0));
  FusionAssessment a = AssessCandidate(With(v), p);
  EXPECT_EQ(a.counted_misses, 1);
  EXPECT_NEAR(a.log_odds, p.max_search_log_odds + miss, 1e-9);
  EXPECT_EQ(a.decision, FusionDecision::kNone);  // 0.49: a person the first close look missed gets another
  v.push_back(Missed("scout_3", 0.0, 0.5, 130, 18.0));
  a = AssessCandidate(With(v), p);
  EXPECT_NEAR(a.log_odds, p.max_search_log_odds + 2 * miss, 1e-9);
  EXPECT_LT(a.belief, p.reject_belief);
  EXPECT_EQ(a.decision, FusionDecision::kReject);
  EXPECT_FALSE(a.undecided);
}

TEST(SightingFusion, ParametersThatWouldLetOneViewConfirmAreRefused) {
  FusionParams p;
  EXPECT_EQ(FusionParamsProblem(p), "");
  p.confirm_views = 1;
  EXPECT_EQ(FusionParamsProblem(p), "confirm_views must be >= 2: a single view never confirms");
  p = {};
  p.false_repeat = 0.9;
  EXPECT_EQ(FusionParamsProblem(p), "false_repeat must be in [0, detector_recall): a miss must count against a candidate");
}

// ---- the leader -----------------------------------------------------------------------------

class Mission {
 public:
  void Apply(const raft::MissionCommand& c) {
    const raft::ApplyResult r = state.Apply(++index_, c);
    ASSERT_TRUE(r.accepted) << raft::CommandName(c) << ": " << r.reason;
  }
  raft::MissionState state;

 private:
  std::uint64_t index_ = 0;
};

template <typename T>
const T* Find(const MissionOutput& out) {
  for (const raft::MissionCommand& c : out.proposals) {
    if (const T* t = std::get_if<T>(&c)) return t;
  }
  return nullptr;
}

std::string Line(const MissionOutput& out, const std::string& event) {
  for (const LogEvent& e : out.events) {
    const std::string s = e.str();
    if (s.find("event=" + event + " ") != std::string::npos) return s;
  }
  return "";
}

RosterEntry Scout(const std::string& name, const std::string& mode, Eigen::Vector2d at) {
  RosterEntry r;
  r.name = name;
  r.mode = mode;
  r.position_m = at;
  return r;
}

class LeaderSightings : public ::testing::Test {
 protected:
  void SetUp() override {
    m.Apply(raft::AssignSectors{{{"scout_1", -90, -90, 0, 90}, {"scout_2", 0, -90, 90, 90}}});
    m.Apply(raft::StartSearch{});
    roster = {Scout("scout_1", "searching", {-40, 0}), Scout("scout_2", "swept", {60, 10}),
              Scout("scout_3", "searching", {20, 50})};
  }
  MissionOutput StepAt(double t) {
    MissionOutput out;
    leader.Step(t, m.state, roster, &out);
    return out;
  }
  Mission m;
  LeaderPlanner leader{LeaderConfig{.name = "scout_1", .search_area = {-90, -90, 90, 90}}};
  std::vector<RosterEntry> roster;
};

TEST_F(LeaderSightings, ConfirmsOnlyOnASecondViewAndLogsTheEvidence) {
  leader.Track(0.0, m.state);
  m.Apply(raft::ReportSighting{"scout_1", 1, 40, 10, 0.95, 40, 0, 30, 20.0});
  MissionOutput out = StepAt(20.5);
  EXPECT_EQ(Find<raft::ConfirmSighting>(out), nullptr);
  const std::string sighting = Line(out, "sighting");
  EXPECT_NE(sighting.find("candidate=1 reporter=scout_1 seen=true confidence=0.950"), std::string::npos) << sighting;
  EXPECT_NE(sighting.find("viewer=40.0:0.0:30.0 capture_t=20.00 belief=0.950"), std::string::npos) << sighting;
  // The same drone 12 m further on: a second view; the leader decides.
  m.Apply(raft::ReportSighting{"scout_1", 2, 40.5, 10, 0.9, 40, 12, 30, 21.7});
  out = StepAt(22.0);
  const auto* confirm = Find<raft::ConfirmSighting>(out);
  ASSERT_NE(confirm, nullptr);
  EXPECT_EQ(confirm->candidate, 1u);
  EXPECT_NEAR(confirm->belief, 1 / (1 + std::exp(-(Logit(0.95) + Logit(0.9)))), 1e-9);
  m.Apply(*confirm);
  out = StepAt(22.5);
  const std::string confirmed = Line(out, "confirmed");
  EXPECT_NE(confirmed.find("victim=1 decided_belief=0.994 candidate=1"), std::string::npos) << confirmed;
  EXPECT_NE(confirmed.find("drones=scout_1,scout_1 confidences=0.950,0.900 viewers=40.0:0.0:30.0,40.0:12.0:30.0 "
                           "view_t=20.00,21.70"),
            std::string::npos)
      << confirmed;
  // Confirmed: converged on and rescued like any victim.
  ASSERT_NE(Find<raft::ConvergeOn>(out), nullptr);
}

TEST_F(LeaderSightings, SendsTheNearestIdleScoutToRevisitThenRejectsAFalseAlarm) {
  leader.Track(0.0, m.state);
  m.Apply(raft::ReportSighting{"scout_3", 1, 40, 10, 0.9, 30, 10, 30, 20.0});
  EXPECT_EQ(Find<raft::RequestRevisit>(StepAt(25.0)), nullptr);  // a second view may still come
  MissionOutput out = StepAt(30.0);                               // revisit_after_s later: none came
  const auto* rv = Find<raft::RequestRevisit>(out);
  ASSERT_NE(rv, nullptr);
  EXPECT_EQ(rv->drone, "scout_2");  // swept (idle) beats the nearer but busy scout_3
  m.Apply(*rv);
  // Undecided while a candidate is pending: no ReturnHome even with every scout done.
  roster[0].mode = "swept";
  roster[2].mode = "swept";
  leader.Track(45.0, m.state);
  EXPECT_EQ(Find<raft::ReturnHome>(StepAt(45.0)), nullptr);
  // scout_2 looked from overhead and saw nothing; twice more after new requests.
  double t = 50.0;
  std::uint64_t seq = 1;
  for (int look = 0; look < 3; ++look, t += 20.0) {
    m.Apply(raft::ReportMiss{"scout_2", seq++, 1, 40.5, 10, 30, t});
    out = StepAt(t + 0.5);
    if (look < 2) {
      EXPECT_EQ(Find<raft::RejectSighting>(out), nullptr) << look;
      m.Apply(raft::RequestRevisit{1, "scout_2", t + 1});
    }
  }
  const auto* reject = Find<raft::RejectSighting>(out);
  ASSERT_NE(reject, nullptr);
  EXPECT_LT(reject->belief, 0.2);
  m.Apply(*reject);
  out = StepAt(t + 1.0);
  const std::string rejected = Line(out, "rejected");
  EXPECT_NE(rejected.find("reason=belief"), std::string::npos) << rejected;
  EXPECT_NE(rejected.find("drones=scout_3,scout_2,scout_2,scout_2 confidences=0.900,0.000,0.000,0.000"),
            std::string::npos)
      << rejected;
  EXPECT_TRUE(m.state.victims().empty());  // nobody goes to rescue a false alarm
  EXPECT_NE(Find<raft::ReturnHome>(StepAt(t + 12.0)), nullptr);
}

TEST_F(LeaderSightings, ACandidateWhoseRevisitsRanOutIsLoggedAsUndecided) {
  // rubble20 on 2026-11-28 logged every such rejection reason=belief (with decided_belief up to 0.94).
  leader.Track(0.0, m.state);
  m.Apply(raft::ReportSighting{"scout_3", 1, 40, 10, 0.7, 30, 10, 30, 20.0});
  // Each revisit sees something, too weakly to move the belief (a 0.5 view adds no log-odds).
  double t = 40.0;
  std::uint64_t seq = 1;
  for (int look = 0; look < 3; ++look, t += 20.0) {
    m.Apply(raft::RequestRevisit{1, "scout_2", t});
    m.Apply(raft::ReportSighting{"scout_2", seq++, 40.2, 10, 0.5, 40, 10 + 12.0 * look, 30, t + 5});
  }
  MissionOutput out = StepAt(t);
  const auto* reject = Find<raft::RejectSighting>(out);
  ASSERT_NE(reject, nullptr);
  EXPECT_NEAR(reject->belief, 0.7, 1e-9);
  m.Apply(*reject);
  out = StepAt(t + 1.0);
  const std::string rejected = Line(out, "rejected");
  EXPECT_NE(rejected.find("reason=undecided decided_belief=0.700"), std::string::npos) << rejected;
}

TEST_F(LeaderSightings, ARevisitWhoseDroneIsGoneGoesToAnother) {
  leader.Track(0.0, m.state);
  m.Apply(raft::ReportSighting{"scout_3", 1, 40, 10, 0.9, 30, 10, 30, 20.0});
  m.Apply(raft::RequestRevisit{1, "scout_2", 30.0});
  EXPECT_EQ(Find<raft::RequestRevisit>(StepAt(31.0)), nullptr);
  roster[1].age_s = 20.0;  // scout_2 silent: gone
  const auto* rv = Find<raft::RequestRevisit>(StepAt(40.0));
  ASSERT_NE(rv, nullptr);
  EXPECT_NE(rv->drone, "scout_2");
}

// ---- the scout -------------------------------------------------------------------------------

MissionInput At(double t, const raft::MissionState& m, const Vector3d& p, std::span<const GroundDetection> d = {}) {
  MissionInput in;
  in.t_s = t;
  in.mission = &m;
  in.position_m = p;
  in.detections = d;
  return in;
}

// A mission searching with scout_1 on sector (0, 0)-(60, 150).
void StartSearching(Mission* m) {
  m->Apply(raft::AssignSectors{{{"scout_1", 0, 0, 60, 150}}});
  m->Apply(raft::StartSearch{});
}

TEST(ScoutRevisit, FliesOverTheCandidateLooksAndReportsAMissThenResumesItsSweep) {
  Mission m;
  StartSearching(&m);
  m.Apply(raft::ReportSighting{"scout_2", 1, 100, 40, 0.9, 100, 30, 30, 5.0});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0), .revisit_look_s = 2.0});
  MissionOutput out;
  s.Step(At(0.0, m.state, {0, 0, 0.23}), &out);
  s.Step(At(1.0, m.state, {0, 0, 30}), &out);
  s.Step(At(2.0, m.state, {10, 10, 30}), &out);
  ASSERT_EQ(out.mode, "searching");
  const std::size_t lane = s.lane_index();
  m.Apply(raft::RequestRevisit{1, "scout_1", 20.0});
  s.Step(At(20.5, m.state, {10, 20, 30}), &out);
  EXPECT_EQ(out.mode, "revisiting");
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kFlock);
  EXPECT_TRUE(out.setpoint.target_m.isApprox(Vector3d(100, 40, 30)));
  // Over the spot: a 2 s look, nothing seen, then the miss with where it looked from.
  s.Step(At(30.0, m.state, {99.5, 40, 30}), &out);
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kPosition);
  EXPECT_TRUE(out.proposals.empty());
  s.Step(At(31.9, m.state, {99.6, 40, 30}), &out);
  EXPECT_TRUE(out.proposals.empty());
  s.Step(At(32.0, m.state, {99.6, 40.1, 30}), &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  const auto& miss = std::get<raft::ReportMiss>(out.proposals[0]);
  EXPECT_EQ(miss.candidate, 1u);
  EXPECT_DOUBLE_EQ(miss.viewer_x_m, 99.6);
  EXPECT_DOUBLE_EQ(miss.viewer_height_m, 30);
  EXPECT_DOUBLE_EQ(miss.t_s, 32.0);
  m.Apply(miss);
  // The committed miss completes the revisit: back to the sweep where it left it.
  s.Step(At(32.5, m.state, {99.6, 40.1, 30}), &out);
  EXPECT_EQ(out.mode, "searching");
  EXPECT_EQ(s.lane_index(), lane);
}

// A candidate beyond where a drone can hover (by the geofence, whose wall repulsion holds a drone
// WallStandoffM off: here the area ends at 74 m) is looked at from the nearest point that can be
// reached, and the look ends.
TEST(ScoutRevisit, ACandidateByTheFenceIsLookedAtFromTheNearestReachablePoint) {
  Mission m;
  StartSearching(&m);
  m.Apply(raft::ReportSighting{"scout_2", 1, 40, 78, 0.9, 40, 70, 30, 5.0});
  m.Apply(raft::RequestRevisit{1, "scout_1", 20.0});
  ScoutBehaviour s({.name = "scout_1",
                    .home_m = Vector3d(0, 0, 0),
                    .revisit_look_s = 2.0,
                    .revisit_area = {-74, -74, 74, 74}});
  MissionOutput out;
  s.Step(At(0.0, m.state, {0, 0, 0.23}), &out);
  s.Step(At(1.0, m.state, {0, 0, 30}), &out);
  s.Step(At(21.0, m.state, {30, 50, 30}), &out);
  ASSERT_EQ(out.mode, "revisiting");
  EXPECT_TRUE(out.setpoint.target_m.isApprox(Vector3d(40, 74, 30)));
  s.Step(At(30.0, m.state, {40, 73.5, 30}), &out);  // there (0.5 m), 4.5 m from the candidate
  s.Step(At(32.0, m.state, {40, 73.6, 30}), &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  const auto& miss = std::get<raft::ReportMiss>(out.proposals[0]);
  EXPECT_DOUBLE_EQ(miss.viewer_y_m, 73.6);
  m.Apply(miss);
  EXPECT_TRUE(m.state.FindCandidate(1)->revisit_drone.empty());  // the revisit is done ...
  EXPECT_EQ(AssessCandidate(*m.state.FindCandidate(1), FusionParams{}).counted_misses, 1);  // ... and counts
}

// A detection beyond the geofence (a frame at the field's edge sees past it) is not reported.
TEST(ScoutRevisit, ADetectionBeyondTheSightingAreaIsNotReported) {
  Mission m;
  StartSearching(&m);
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0), .sighting_area = {-80, -80, 80, 80}});
  MissionOutput out;
  s.Step(At(0.0, m.state, {0, 0, 0.23}), &out);
  s.Step(At(1.0, m.state, {0, 0, 30}), &out);
  GroundDetection d;
  d.confidence = 0.93;
  d.capture_time_s = 4.0;
  d.viewer_m = {40, 72, 30};
  d.position_m = {40, 82.6, 0};
  std::vector<GroundDetection> dets = {d};
  s.Step(At(4.1, m.state, {40, 72, 30}, dets), &out);
  EXPECT_TRUE(out.proposals.empty());
  dets[0].position_m = {40, 79.0, 0};  // inside: reported
  s.Step(At(4.2, m.state, {40, 72, 30}, dets), &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  EXPECT_DOUBLE_EQ(std::get<raft::ReportSighting>(out.proposals[0]).y_m, 79.0);
}

// A candidate at (100, 40) that scout_2 saw, which the leader sent scout_1 to revisit at t = 20 s.
void CandidateToRevisit(Mission* m) {
  m->Apply(raft::ReportSighting{"scout_2", 1, 100, 40, 0.9, 100, 30, 30, 5.0});
  m->Apply(raft::RequestRevisit{1, "scout_1", 20.0});
}
// The scout on the ground at t = 0 and at its 30 m search altitude at t = 1 s.
void TakeOff(ScoutBehaviour& s, const Mission& m, MissionOutput* out) {
  s.Step(At(0.0, m.state, {0, 0, 0.23}), out);
  s.Step(At(1.0, m.state, {0, 0, 30}), out);
}

// With a look altitude the revisit flies out at the search altitude, descends over the spot, and
// only a view from the look altitude answers (the descent's are views of the same object from the
// search model's heights: not sent).
TEST(ScoutRevisit, ACloseLookDescendsOverTheCandidateAndOnlyItsViewAnswers) {
  Mission m;
  StartSearching(&m);
  CandidateToRevisit(&m);
  ScoutBehaviour s({.name = "scout_1",
                    .home_m = Vector3d(0, 0, 0),
                    .revisit_look_s = 2.0,
                    .revisit_look_altitude_m = 18.0});
  MissionOutput out;
  TakeOff(s, m, &out);
  s.Step(At(21.0, m.state, {60, 40, 30}), &out);
  ASSERT_EQ(out.mode, "revisiting");
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kFlock);
  EXPECT_TRUE(out.setpoint.target_m.isApprox(Vector3d(100, 40, 30)));
  s.Step(At(28.0, m.state, {95, 40, 30}), &out);
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kPosition);
  EXPECT_TRUE(out.setpoint.target_m.isApprox(Vector3d(100, 40, 18)));
  GroundDetection d;
  d.position_m = {100.4, 39.8, 0};
  d.confidence = 0.9;
  d.capture_time_s = 29.0;
  d.viewer_m = {99, 40, 26};
  std::vector<GroundDetection> dets = {d};
  s.Step(At(29.1, m.state, {99, 40, 26}, dets), &out);
  EXPECT_TRUE(out.proposals.empty());
  s.Step(At(33.0, m.state, {100, 40, 24}), &out);  // over it but not down yet: no look, no miss
  EXPECT_TRUE(out.proposals.empty());
  dets[0].viewer_m = {100, 40, 18.2};
  dets[0].capture_time_s = 35.0;
  s.Step(At(35.1, m.state, {100, 40, 18.2}, dets), &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  const auto& seen = std::get<raft::ReportSighting>(out.proposals[0]);
  EXPECT_DOUBLE_EQ(seen.viewer_height_m, 18.2);
  m.Apply(seen);
  EXPECT_TRUE(m.state.FindCandidate(1)->revisit_drone.empty());
  EXPECT_EQ(AssessCandidate(*m.state.FindCandidate(1), WithCloseLooks()).close_detections, 1);
}

// The last revisit_approach_m to the spot are flown in position mode, descending to the look
// altitude on the way.
TEST(ScoutRevisit, TheLastStretchIsFlownInPositionModeFromTheApproachDistance) {
  Mission m;
  StartSearching(&m);
  CandidateToRevisit(&m);
  ScoutBehaviour s({.name = "scout_1",
                    .home_m = Vector3d(0, 0, 0),
                    .revisit_look_altitude_m = 18.0,
                    .revisit_approach_m = 17.5});
  MissionOutput out;
  TakeOff(s, m, &out);
  s.Step(At(21.0, m.state, {80, 40, 30}), &out);  // 20 m off: flocking at the search altitude
  ASSERT_EQ(out.mode, "revisiting");
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kFlock);
  s.Step(At(23.0, m.state, {84, 40, 30}), &out);  // 16 m off: straight there, down to look
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kPosition);
  EXPECT_TRUE(out.setpoint.target_m.isApprox(Vector3d(100, 40, 18)));
}

TEST(ScoutRevisit, ADetectionThereIsTheRevisitsAnswer) {
  Mission m;
  StartSearching(&m);
  m.Apply(raft::ReportSighting{"scout_2", 1, 100, 40, 0.9, 100, 30, 30, 5.0});
  m.Apply(raft::RequestRevisit{1, "scout_1", 20.0});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0)});
  MissionOutput out;
  s.Step(At(0.0, m.state, {0, 0, 0.23}), &out);
  s.Step(At(1.0, m.state, {0, 0, 30}), &out);
  s.Step(At(21.0, m.state, {90, 40, 30}), &out);
  ASSERT_EQ(out.mode, "revisiting");
  GroundDetection d;
  d.position_m = {100.4, 39.8, 0};
  d.confidence = 0.93;
  d.capture_time_s = 24.0;
  d.viewer_m = {96, 40, 30};
  const std::vector<GroundDetection> dets = {d};
  s.Step(At(24.1, m.state, {96, 40, 30}, dets), &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  const auto& seen = std::get<raft::ReportSighting>(out.proposals[0]);
  m.Apply(seen);
  EXPECT_TRUE(m.state.FindCandidate(1)->revisit_drone.empty());
  EXPECT_EQ(m.state.FindCandidate(1)->revisits, 1u);
  for (double t = 24.2; t < 30; t += 0.1) {
    s.Step(At(t, m.state, {100, 40, 30}), &out);
    EXPECT_EQ(std::get_if<raft::ReportMiss>(out.proposals.empty() ? nullptr : &out.proposals[0]), nullptr);
  }
}

}  // namespace
}  // namespace swarmbox::swarm
