// Losing a drone during the SAR mission (issues #7 and #8), step by step on a simulated clock:
// LeaderPlanner notices a member whose state stopped (RosterEntry::age_s past member_timeout_s),
// hands its sectors to live scouts through a committed AssignSectors, finishes the search only
// when every sector has a live owner that swept it, and a new leader rebuilds all of it from the
// committed MissionState (Raft §5.3: every drone applies the same log); ScoutBehaviour sweeps
// every sector it owns and goes back to work for a late hand-over.
#include <algorithm>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "swarmbox/swarm/leader_planner.hpp"
#include "swarmbox/swarm/scout_behaviour.hpp"
#include "swarmbox/swarm/detection.hpp"

namespace swarmbox::swarm {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using raft::MissionPhase;

const Rect kArea{-90, -90, 90, 90};

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

bool HasEvent(const MissionOutput& out, const std::string& name, const std::string& also = "") {
  for (const LogEvent& e : out.events) {
    const std::string s = e.str();
    if (s.find("event=" + name) != std::string::npos && s.find(also) != std::string::npos) return true;
  }
  return false;
}

template <typename T>
const T* Find(const MissionOutput& out) {
  for (const raft::MissionCommand& c : out.proposals) {
    if (const T* t = std::get_if<T>(&c)) return t;
  }
  return nullptr;
}

// The proposal of type T (a copy); a failure and T{} when there is none.
template <typename T>
T Get(const MissionOutput& out) {
  const T* t = Find<T>(out);
  if (t == nullptr) {
    ADD_FAILURE() << "no such proposal";
    return T{};
  }
  return *t;
}

RosterEntry Entry(const std::string& name, const std::string& mode, double age_s = 0.2,
                  Role role = Role::kScout, Vector2d at = Vector2d::Zero()) {
  RosterEntry r;
  r.name = name;
  r.role = role;
  r.mode = mode;
  r.age_s = age_s;
  r.position_m = at;
  return r;
}

// Three scouts (scout_1 leads) and a lifter; the search started over kArea in three strips.
class FailoverTest : public ::testing::Test {
 protected:
  FailoverTest() {
    const std::vector<std::string> scouts = {"scout_1", "scout_2", "scout_3"};
    m.Apply(raft::AssignSectors{PartitionArea(kArea, scouts)});
    m.Apply(raft::StartSearch{});
  }
  static LeaderPlanner Planner(const std::string& name) {
    return LeaderPlanner({.name = name, .search_area = kArea, .retry_s = 2.0});
  }
  std::vector<RosterEntry> Roster(const std::string& m1, const std::string& m2, const std::string& m3,
                                  double age3 = 0.2) const {
    return {Entry("scout_1", m1, 0.0, Role::kScout, {-60, 0}), Entry("scout_2", m2, 0.2, Role::kScout, {0, 0}),
            Entry("scout_3", m3, age3, Role::kScout, {60, 0}), Entry("lifter", "on_ground", 0.2, Role::kLifter)};
  }
  // Area of the sectors each drone owns [m^2].
  double AreaOf(const std::string& drone) const {
    double a = 0;
    for (const raft::Sector& s : m.state.sectors()) {
      if (s.drone == drone) a += (s.x_max_m - s.x_min_m) * (s.y_max_m - s.y_min_m);
    }
    return a;
  }
  Mission m;
};

TEST_F(FailoverTest, ALiveScoutWithinTheTimeoutKeepsItsSector) {
  LeaderPlanner leader = Planner("scout_1");
  MissionOutput out;
  leader.Step(20.0, m.state, Roster("searching", "searching", "searching", 5.9), &out);
  EXPECT_TRUE(out.proposals.empty());
  EXPECT_FALSE(HasEvent(out, "member_lost"));
}

TEST_F(FailoverTest, AScoutLostMidSweepHasItsSectorSplitAmongTheLiveScouts) {
  LeaderPlanner leader = Planner("scout_1");
  MissionOutput out;
  leader.Step(20.0, m.state, Roster("searching", "searching", "searching", 6.5), &out);
  EXPECT_TRUE(HasEvent(out, "member_lost", "drone=scout_3"));
  EXPECT_TRUE(HasEvent(out, "sector_reassigned", "from=scout_3 to=scout_1,scout_2"));
  ASSERT_NE(Find<raft::AssignSectors>(out), nullptr);
  ASSERT_EQ(out.proposals.size(), 1u);  // no ReturnHome: the lost sector is not searched yet
  m.Apply(Get<raft::AssignSectors>(out));
  // The whole 60 m x 180 m strip of scout_3, cut across its length into two 60 x 90 pieces.
  EXPECT_DOUBLE_EQ(AreaOf("scout_3"), 0.0);
  EXPECT_DOUBLE_EQ(AreaOf("scout_1"), 60.0 * 180.0 + 60.0 * 90.0);
  EXPECT_DOUBLE_EQ(AreaOf("scout_2"), 60.0 * 180.0 + 60.0 * 90.0);
  ASSERT_EQ(m.state.sectors().size(), 4u);
  EXPECT_EQ(m.state.sectors()[2], (raft::Sector{"scout_1", 30, -90, 90, 0}));
  EXPECT_EQ(m.state.sectors()[3], (raft::Sector{"scout_2", 30, 0, 90, 90}));
  // Committed: nothing more to hand over, and member_lost is said once.
  out.Clear();
  leader.Step(23.0, m.state, Roster("searching", "searching", "searching", 9.5), &out);
  EXPECT_TRUE(out.proposals.empty());
  EXPECT_FALSE(HasEvent(out, "member_lost"));
}

TEST_F(FailoverTest, AnUncommittedHandOverIsReproposedAfterRetry) {
  LeaderPlanner leader = Planner("scout_1");
  MissionOutput out;
  leader.Step(20.0, m.state, Roster("searching", "searching", "searching", 7.0), &out);
  ASSERT_NE(Find<raft::AssignSectors>(out), nullptr);
  const raft::AssignSectors first = Get<raft::AssignSectors>(out);
  out.Clear();
  leader.Step(21.0, m.state, Roster("searching", "searching", "searching", 8.0), &out);
  EXPECT_EQ(Find<raft::AssignSectors>(out), nullptr);  // within retry_s
  leader.Step(22.5, m.state, Roster("searching", "searching", "searching", 9.5), &out);
  ASSERT_NE(Find<raft::AssignSectors>(out), nullptr);
  EXPECT_EQ(Get<raft::AssignSectors>(out), first);  // the same plan: a double commit is harmless
}

TEST_F(FailoverTest, TheSearchEndsOnlyWhenTheHandedOverSectorsAreSweptBySomeoneAlive) {
  LeaderPlanner leader = Planner("scout_1");
  MissionOutput out;
  // scout_1 and scout_2 swept theirs; scout_3 fell silent mid-sweep: no ReturnHome.
  leader.Step(100.0, m.state, Roster("swept", "swept", "searching", 7.0), &out);
  EXPECT_EQ(Find<raft::ReturnHome>(out), nullptr);
  ASSERT_NE(Find<raft::AssignSectors>(out), nullptr);
  m.Apply(Get<raft::AssignSectors>(out));
  out.Clear();
  // Just committed: the receivers' "swept" may predate it. Not finished within the settle time.
  leader.Step(101.0, m.state, Roster("swept", "swept", "searching", 8.0), &out);
  leader.Step(109.0, m.state, Roster("swept", "swept", "searching", 16.0), &out);
  EXPECT_EQ(Find<raft::ReturnHome>(out), nullptr);
  leader.Step(115.0, m.state, Roster("searching", "searching", "searching", 22.0), &out);
  EXPECT_EQ(Find<raft::ReturnHome>(out), nullptr);
  leader.Step(140.0, m.state, Roster("swept", "searching", "searching", 47.0), &out);
  EXPECT_EQ(Find<raft::ReturnHome>(out), nullptr);  // scout_2 still sweeps its piece
  // Both pieces swept; the dead scout's last "searching" does not count.
  leader.Step(160.0, m.state, Roster("swept", "landed", "searching", 67.0), &out);
  EXPECT_NE(Find<raft::ReturnHome>(out), nullptr);
  m.Apply(raft::ReturnHome{});
  out.Clear();
  // RETURN: the dead drone never lands, the live ones do.
  leader.Step(200.0, m.state, Roster("landed", "landed", "searching", 107.0), &out);
  EXPECT_NE(Find<raft::CompleteMission>(out), nullptr);
}

TEST_F(FailoverTest, WithNoLiveScoutTheLostSectorStaysAndTheSearchIsNotFinished) {
  LeaderPlanner leader = Planner("lifter");
  MissionOutput out;
  std::vector<RosterEntry> r = {Entry("scout_1", "searching", 9.0), Entry("scout_2", "swept", 9.0),
                                Entry("scout_3", "swept", 9.0), Entry("lifter", "on_ground", 0.0, Role::kLifter)};
  leader.Step(100.0, m.state, r, &out);
  EXPECT_TRUE(out.proposals.empty());
  EXPECT_TRUE(HasEvent(out, "member_lost", "drone=scout_1"));
}

// The leader itself is lost: a follower that becomes leader has only the committed state and the
// roster. It hands the old leader's sector over, and continues the old leader's own duties: the
// victim it confirmed but did not converge on, then the rescue.
TEST_F(FailoverTest, ANewLeaderRebuildsFromTheCommittedStateAndTakesOverTheLeadersDuties) {
  LeaderPlanner old_leader = Planner("scout_1");
  LeaderPlanner next = Planner("scout_2");
  MissionOutput out;
  // scout_3 was lost first; the old leader's hand-over is committed.
  next.Track(10.0, m.state);
  old_leader.Step(20.0, m.state, Roster("searching", "searching", "searching", 7.0), &out);
  m.Apply(Get<raft::AssignSectors>(out));
  next.Track(20.3, m.state);
  // A victim confirmed (two sightings and the decision committed), then the old leader is killed
  // before ConvergeOn.
  m.Apply(raft::ReportSighting{"scout_1", 1, 40, 40, 0.9, 30, 40, 30, 25});
  m.Apply(raft::ReportSighting{"scout_2", 1, 41, 40, 0.9, 50, 40, 30, 26});
  m.Apply(raft::ConfirmSighting{1, 0.99});
  ASSERT_EQ(m.state.victims().size(), 1u);
  next.Track(30.0, m.state);
  out.Clear();
  // The new leader: the old leader silent 7 s, scout_3 long gone, scout_2 alone to search.
  std::vector<RosterEntry> r = {Entry("scout_1", "searching", 7.0, Role::kScout, {-60, 0}),
                                Entry("scout_2", "searching", 0.0, Role::kScout, {0, 0}),
                                Entry("scout_3", "searching", 17.0, Role::kScout, {60, 0}),
                                Entry("lifter", "on_ground", 0.2, Role::kLifter)};
  next.Step(37.0, m.state, r, &out);
  EXPECT_TRUE(HasEvent(out, "member_lost", "drone=scout_1"));
  EXPECT_TRUE(HasEvent(out, "member_lost", "drone=scout_3"));
  ASSERT_NE(Find<raft::AssignSectors>(out), nullptr);
  ASSERT_NE(Find<raft::ConvergeOn>(out), nullptr);
  EXPECT_EQ(Get<raft::ConvergeOn>(out).victim_id, 1u);
  m.Apply(Get<raft::AssignSectors>(out));
  m.Apply(Get<raft::ConvergeOn>(out));
  EXPECT_DOUBLE_EQ(AreaOf("scout_2"), 180.0 * 180.0);  // everything, its own and both lost ones
  out.Clear();
  next.Step(38.0, m.state, r, &out);
  ASSERT_NE(Find<raft::BeginRescue>(out), nullptr);
  EXPECT_EQ(Get<raft::BeginRescue>(out).lifter, "lifter");
  EXPECT_EQ(Find<raft::AssignSectors>(out), nullptr);
}

// A follower's Track() saw the last hand-over long ago: as new leader it need not wait the
// settle time again; a planner that never tracked (a restarted agent) waits it once.
TEST_F(FailoverTest, ANewLeaderWaitsTheSettleTimeOnlyForAHandOverItHasNotSeenSettle) {
  LeaderPlanner tracked = Planner("scout_2");
  LeaderPlanner fresh = Planner("scout_2");
  tracked.Track(10.0, m.state);
  const std::vector<RosterEntry> r = {Entry("scout_1", "landed", 0.2), Entry("scout_2", "landed", 0.0),
                                      Entry("scout_3", "landed", 0.2), Entry("lifter", "on_ground", 0.2, Role::kLifter)};
  MissionOutput out;
  tracked.Step(50.0, m.state, r, &out);
  EXPECT_NE(Find<raft::ReturnHome>(out), nullptr);
  out.Clear();
  fresh.Step(50.0, m.state, r, &out);
  EXPECT_EQ(Find<raft::ReturnHome>(out), nullptr);
  fresh.Step(60.0, m.state, r, &out);
  EXPECT_NE(Find<raft::ReturnHome>(out), nullptr);
}

// A scout taken for lost that is heard again (a long radio cut): its sector has gone to others;
// it is a live scout without a sector, which neither blocks the end of the search nor gets its
// sector back, and it is the first choice for the next hand-over (it idles in the air).
TEST_F(FailoverTest, AScoutThatComesBackIsIdleAndTakesTheNextHandOver) {
  LeaderPlanner leader = Planner("scout_1");
  MissionOutput out;
  leader.Step(20.0, m.state, Roster("searching", "searching", "searching", 8.0), &out);
  m.Apply(Get<raft::AssignSectors>(out));
  out.Clear();
  leader.Step(30.0, m.state, Roster("searching", "searching", "awaiting_sector", 0.2), &out);
  EXPECT_TRUE(HasEvent(out, "member_back", "drone=scout_3"));
  EXPECT_TRUE(out.proposals.empty());
  // scout_2 is lost now: its strip (60 x 180) and the piece it had taken over (60 x 90) are each
  // split between scout_3 (idle: first) and scout_1.
  std::vector<RosterEntry> r = {Entry("scout_1", "searching", 0.0, Role::kScout, {-60, 0}),
                                Entry("scout_2", "searching", 6.5, Role::kScout, {0, 0}),
                                Entry("scout_3", "awaiting_sector", 0.2, Role::kScout, {9, 0}),
                                Entry("lifter", "on_ground", 0.2, Role::kLifter)};
  out.Clear();
  leader.Step(40.0, m.state, r, &out);
  ASSERT_NE(Find<raft::AssignSectors>(out), nullptr);
  m.Apply(Get<raft::AssignSectors>(out));
  EXPECT_DOUBLE_EQ(AreaOf("scout_2"), 0.0);
  EXPECT_DOUBLE_EQ(AreaOf("scout_3"), 60.0 * 90.0 + 60.0 * 45.0);
  EXPECT_DOUBLE_EQ(AreaOf("scout_1"), 60.0 * 180.0 + 60.0 * 90.0 + 60.0 * 90.0 + 60.0 * 45.0);
  // Without a sector and idle, a came-back scout does not hold up the end.
  Mission fresh;
  fresh.Apply(raft::AssignSectors{{{"scout_1", -90, -90, 90, 90}}});
  fresh.Apply(raft::StartSearch{});
  LeaderPlanner l2 = Planner("scout_1");
  l2.Track(0.0, fresh.state);
  out.Clear();
  l2.Step(50.0, fresh.state, Roster("swept", "awaiting_sector", "awaiting_sector"), &out);
  EXPECT_NE(Find<raft::ReturnHome>(out), nullptr);
}

TEST_F(FailoverTest, ADroneNeverHeardIsLostOnlyAfterTheTimeoutFromTheStart) {
  LeaderPlanner leader = Planner("scout_1");
  const std::vector<RosterEntry> r = {Entry("scout_1", "searching", 0.0), Entry("scout_2", "searching", 0.2),
                                      Entry("lifter", "on_ground", 0.2, Role::kLifter)};
  MissionOutput out;
  leader.Step(100.0, m.state, r, &out);  // a restarted leader: scout_3 not heard yet
  EXPECT_EQ(Find<raft::AssignSectors>(out), nullptr);
  leader.Step(106.5, m.state, r, &out);
  ASSERT_NE(Find<raft::AssignSectors>(out), nullptr);
}

// ---- both clocks (rtf 0: the radio delivers in wall time, the world runs many times faster) --

// The roster of Roster() with scout_3 silent `sim_s` simulated and `wall_s` wall seconds, the
// others heard 0.2 s ago on both clocks.
std::vector<RosterEntry> Aged(double sim_s, double wall_s) {
  std::vector<RosterEntry> r = {Entry("scout_1", "searching", 0.0, Role::kScout, {-60, 0}),
                                Entry("scout_2", "searching", 0.2, Role::kScout, {0, 0}),
                                Entry("scout_3", "searching", sim_s, Role::kScout, {60, 0}),
                                Entry("lifter", "on_ground", 0.2, Role::kLifter)};
  for (RosterEntry& e : r) e.wall_age_s = e.name == "scout_3" ? wall_s : std::min(e.age_s, 0.2);
  return r;
}

// At rtf 0 a sample held back 0.8 s of wall time (a starved thread, DDS repairing a loss) is
// 6.5 s old on the simulated clock: a live member, not a lost one.
TEST_F(FailoverTest, SilentSixSimulatedSecondsButUnderASecondOfWallTimeIsNotLost) {
  LeaderPlanner leader = Planner("scout_1");
  MissionOutput out;
  leader.Step(20.0, m.state, Aged(6.5, 0.8), &out, 1000.0);
  EXPECT_FALSE(HasEvent(out, "member_lost"));
  EXPECT_FALSE(HasEvent(out, "sector_reassigned"));
  EXPECT_TRUE(out.proposals.empty());
  EXPECT_TRUE(leader.Alive(Aged(6.5, 0.8)[2]));
  // Even 60 simulated seconds within 2.9 s of wall time (a 20x speed-up) is not silence.
  leader.Step(80.0, m.state, Aged(60.0, 2.9), &out, 1002.9);
  EXPECT_FALSE(HasEvent(out, "member_lost"));
  EXPECT_TRUE(out.proposals.empty());
}

// Silent past both floors: lost, and its sector handed over as with the simulated clock alone.
TEST_F(FailoverTest, SilentSixSimulatedAndThreeWallSecondsIsLost) {
  LeaderPlanner leader = Planner("scout_1");
  MissionOutput out;
  leader.Step(20.0, m.state, Aged(6.5, 3.0), &out, 1000.0);
  EXPECT_TRUE(HasEvent(out, "member_lost", "drone=scout_3 role=scout silent_s=6.5 silent_wall_s=3.0"));
  EXPECT_TRUE(HasEvent(out, "sector_reassigned", "from=scout_3 to=scout_1,scout_2"));
  ASSERT_NE(Find<raft::AssignSectors>(out), nullptr);
  // Long on the wall clock but under 6 s simulated (a slow world, rtf < 0.5): still alive.
  LeaderPlanner slow = Planner("scout_1");
  out.Clear();
  slow.Step(20.0, m.state, Aged(5.9, 30.0), &out, 1000.0);
  EXPECT_FALSE(HasEvent(out, "member_lost"));
  EXPECT_TRUE(out.proposals.empty());
}

// At rtf 1 both ages are the same: the 6 s simulated timeout decides, exactly as without a wall
// clock (5.9 s alive, 6.1 s lost), and a member heard again is back.
TEST_F(FailoverTest, AtRealTimeTheSimulatedTimeoutDecidesAsWithoutAWallClock) {
  for (const bool wall : {true, false}) {
    SCOPED_TRACE(wall ? "ages on both clocks" : "no wall clock");
    LeaderPlanner leader = Planner("scout_1");
    const auto roster = [&](double age3) {
      return wall ? Aged(age3, age3) : Roster("searching", "searching", "searching", age3);
    };
    const auto step = [&](double t, double age3, MissionOutput* out) {
      if (wall) {
        leader.Step(t, m.state, roster(age3), out, 500.0 + t);  // rtf 1: wall = sim + offset
      } else {
        leader.Step(t, m.state, roster(age3), out);
      }
    };
    MissionOutput out;
    step(20.0, 5.9, &out);
    EXPECT_FALSE(HasEvent(out, "member_lost"));
    EXPECT_TRUE(out.proposals.empty());
    step(20.2, 6.1, &out);
    EXPECT_TRUE(HasEvent(out, "member_lost", "drone=scout_3"));
    ASSERT_NE(Find<raft::AssignSectors>(out), nullptr);
    out.Clear();
    step(21.0, 0.2, &out);
    EXPECT_TRUE(HasEvent(out, "member_back", "drone=scout_3"));
  }
}

// Never heard (a restarted leader): lost after 6 s of simulated time from the start only once
// 3 s of wall time passed too; without a wall clock (NaN) the simulated time alone decides.
TEST_F(FailoverTest, ADroneNeverHeardIsLostOnlyAfterBothTimeoutsFromTheStart) {
  LeaderPlanner leader = Planner("scout_1");
  std::vector<RosterEntry> r = {Entry("scout_1", "searching", 0.0), Entry("scout_2", "searching", 0.2),
                                Entry("lifter", "on_ground", 0.2, Role::kLifter)};
  for (RosterEntry& e : r) e.wall_age_s = 0.1;
  MissionOutput out;
  leader.Step(100.0, m.state, r, &out, 7.0);
  leader.Step(110.0, m.state, r, &out, 8.0);  // 10 s simulated, 1 s wall: not yet
  EXPECT_EQ(Find<raft::AssignSectors>(out), nullptr);
  leader.Step(110.1, m.state, r, &out, 10.0);
  ASSERT_NE(Find<raft::AssignSectors>(out), nullptr);
}

// ---- scout ---------------------------------------------------------------------------------

MissionInput Input(double t, const Mission& m, const Vector3d& p) {
  MissionInput in;
  in.t_s = t;
  in.mission = &m.state;
  in.position_m = p;
  return in;
}

// Flies the scout's current lanes to their end (arriving at each waypoint); returns the time.
double SweepAll(ScoutBehaviour& s, const Mission& m, double t, MissionOutput* out, int* swept_events) {
  const std::vector<Waypoint> lanes = s.lanes();
  for (const Waypoint& w : lanes) {
    s.Step(Input(t += 1.0, m, w.position_m), out);
    *swept_events += HasEvent(*out, "sector_swept") ? 1 : 0;
  }
  return t;
}

TEST(ScoutHandOver, SweepsEverySectorItOwnsOneAfterTheOther) {
  Mission m;
  m.Apply(raft::AssignSectors{{{"scout_1", 0, 0, 60, 150}, {"scout_2", 60, 0, 120, 150},
                               {"scout_1", 120, 0, 180, 75}}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0)});
  MissionOutput out;
  s.Step(Input(0.0, m, {0, 0, 0.23}), &out);
  s.Step(Input(1.0, m, {0, 0, 30}), &out);  // at altitude: its first sector at once
  EXPECT_TRUE(HasEvent(out, "sector_started", "x_min=0.0"));
  s.Step(Input(1.1, m, {0, 0, 30}), &out);
  ASSERT_EQ(out.mode, "searching");
  int swept = 0;
  double t = SweepAll(s, m, 2.0, &out, &swept);
  EXPECT_EQ(swept, 1);
  EXPECT_EQ(out.mode, "searching");  // on to its second sector at once
  EXPECT_TRUE(HasEvent(out, "sector_started", "x_min=120.0"));
  EXPECT_TRUE(s.lanes().front().position_m.x() > 120.0);
  t = SweepAll(s, m, t, &out, &swept);
  EXPECT_EQ(swept, 2);
  EXPECT_EQ(out.mode, "swept");
  // The same list committed again (a retried AssignSectors): nothing new to sweep.
  m.Apply(raft::AssignSectors{m.state.sectors()});
  s.Step(Input(t + 1.0, m, {150, 30, 30}), &out);
  EXPECT_EQ(out.mode, "swept");
}

TEST(ScoutHandOver, ReportsProgressAfterEachLane) {
  Mission m;
  m.Apply(raft::AssignSectors{{{"scout_1", 0, 0, 100, 150}}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0)});
  MissionOutput out;
  s.Step(Input(0.0, m, {0, 0, 0.23}), &out);
  s.Step(Input(1.0, m, {0, 0, 30}), &out);
  s.Step(Input(1.1, m, {0, 0, 30}), &out);
  const std::vector<Waypoint> lanes = s.lanes();
  ASSERT_GE(lanes.size(), 4u);
  s.Step(Input(2.0, m, lanes[0].position_m), &out);
  EXPECT_FALSE(HasEvent(out, "sector_progress"));
  s.Step(Input(3.0, m, lanes[1].position_m), &out);
  EXPECT_TRUE(HasEvent(out, "sector_progress", "lanes_done=1 lanes=" + std::to_string(lanes.size() / 2)));
}

TEST(ScoutHandOver, GoesBackToWorkWhenHandedASectorAfterItLanded) {
  Mission m;
  m.Apply(raft::AssignSectors{{{"scout_1", 0, 0, 60, 150}}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0), .return_when_swept = true});
  MissionOutput out;
  s.Step(Input(0.0, m, {0, 0, 0.23}), &out);
  s.Step(Input(1.0, m, {0, 0, 30}), &out);
  s.Step(Input(1.1, m, {0, 0, 30}), &out);
  int swept = 0;
  double t = SweepAll(s, m, 2.0, &out, &swept);
  EXPECT_EQ(out.mode, "returning");
  // Handed a sector on its way home: it turns back.
  m.Apply(raft::AssignSectors{{{"scout_1", 0, 0, 60, 150}, {"scout_1", 60, 0, 120, 150}}});
  s.Step(Input(t += 1.0, m, {30, 30, 30}), &out);
  EXPECT_EQ(out.mode, "searching");
  t = SweepAll(s, m, t, &out, &swept);
  EXPECT_EQ(out.mode, "returning");
  s.Step(Input(t += 1.0, m, {0, 0, 5}), &out);
  EXPECT_EQ(out.mode, "landing");
  s.Step(Input(t += 1.0, m, {0, 0, 0.23}), &out);
  EXPECT_EQ(out.mode, "landed");
  // Handed one more on the ground: it takes off again, then searches.
  m.Apply(raft::AssignSectors{{{"scout_1", 0, 0, 60, 150}, {"scout_1", 60, 0, 120, 150},
                               {"scout_1", 120, 0, 180, 150}}});
  s.Step(Input(t += 1.0, m, {0, 0, 0.23}), &out);
  EXPECT_EQ(out.mode, "taking_off");
  EXPECT_EQ(out.setpoint.kind, SetpointKind::kTakeoff);
  s.Step(Input(t += 1.0, m, {0, 0, 30}), &out);
  EXPECT_EQ(out.mode, "searching");
  // Not with a low battery.
  m.Apply(raft::AssignSectors{{{"scout_1", 0, 0, 60, 150}, {"scout_1", 60, 0, 120, 150},
                               {"scout_1", 120, 0, 180, 150}, {"scout_1", 180, 0, 240, 150}}});
  MissionInput low = Input(t += 1.0, m, {130, 10, 30});
  low.battery_low = true;
  s.Step(low, &out);
  EXPECT_EQ(out.mode, "returning");
}


// A report lost on the radio or in a dead leader's log is proposed again until committed.
TEST(ScoutReports, ReproposesAReportUntilTheCommittedStateShowsIt) {
  Mission m;
  m.Apply(raft::AssignSectors{{{"scout_1", 0, 0, 60, 150}}});
  m.Apply(raft::StartSearch{});
  ScoutBehaviour s({.name = "scout_1", .home_m = Vector3d(0, 0, 0), .report_retry_s = 5.0, .report_tries = 3});
  MissionOutput out;
  s.Step(Input(0.0, m, {0, 0, 0.23}), &out);
  s.Step(Input(1.0, m, {0, 0, 30}), &out);
  GroundDetection d;
  d.position_m = {20, 30, 0};
  d.confidence = 0.7;
  std::vector<GroundDetection> dets = {d};
  MissionInput in = Input(2.0, m, {0, 0, 30});
  in.detections = dets;
  s.Step(in, &out);
  ASSERT_EQ(out.proposals.size(), 1u);
  EXPECT_EQ(Get<raft::ReportSighting>(out).seq, 1u);
  s.Step(Input(6.9, m, {10, 10, 30}), &out);
  EXPECT_TRUE(out.proposals.empty());
  s.Step(Input(7.0, m, {10, 10, 30}), &out);  // lost: again, next seq
  ASSERT_EQ(out.proposals.size(), 1u);
  EXPECT_EQ(Get<raft::ReportSighting>(out).seq, 2u);
  EXPECT_DOUBLE_EQ(Get<raft::ReportSighting>(out).x_m, 20.0);
  EXPECT_TRUE(HasEvent(out, "sighting_reported", "retry=1"));
  m.Apply(Get<raft::ReportSighting>(out));  // committed (a candidate: one view)
  s.Step(Input(20.0, m, {10, 10, 30}), &out);
  EXPECT_TRUE(out.proposals.empty());
  // Never committed: report_tries proposals in all, then it is given up.
  d.position_m = {40, 100, 0};
  dets = {d};
  in = Input(30.0, m, {40, 100, 30});
  in.detections = dets;
  s.Step(in, &out);
  int proposals = static_cast<int>(out.proposals.size());
  for (double t = 30.5; t < 80.0; t += 0.5) {
    s.Step(Input(t, m, {40, 60, 30}), &out);
    proposals += static_cast<int>(out.proposals.size());
  }
  EXPECT_EQ(proposals, 3);
}

}  // namespace
}  // namespace swarmbox::swarm
