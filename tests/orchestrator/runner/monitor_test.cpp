// The watch rules as scripted scenarios: inputs in order, the verdict expected (or none).
#include "swarmbox/runner/monitor.hpp"

#include <gtest/gtest.h>

namespace swarmbox::runner {
namespace {

struct Step {
  enum Kind { kLine, kExit, kTick } kind;
  const char* component;
  const char* text;   // line
  double value;       // exit code or wall time
};

struct Scenario {
  const char* name;
  std::vector<Step> steps;
  std::optional<dsl::Outcome> outcome;
  const char* reason;
  double sim_s;
};

std::unique_ptr<dsl::Trial> MakeTrial() {
  auto t = std::make_unique<dsl::Trial>("t");
  t->Add<dsl::Plugin>("physics", dsl::ContainerSpec(), 1);
  t->Add<dsl::Plugin>("scout_1", dsl::ContainerSpec(), 2);
  t->EndOn("event=mission_complete", dsl::Outcome::kSuccess);
  t->EndOn("event=collision", dsl::Outcome::kFailure, "collision");
  t->SetTimeout(dsl::TimeoutPolicy::Sim(dsl::Duration::Seconds(60), dsl::Duration::Seconds(120), "physics"));
  return t;
}

TEST(Monitor, Scenarios) {
  using S = Step;
  const std::vector<Scenario> scenarios = {
      {"mission completes",
       {{S::kLine, "physics", "t=10 event=tick", 0}, {S::kLine, "scout_1", "t=11 event=mission_complete", 0}},
       dsl::Outcome::kSuccess, "matched 'event=mission_complete'", 11},
      {"only the clock component's t ends the trial; others' t is shown",
       {{S::kLine, "scout_1", "t=70 event=tick", 0}, {S::kTick, "", "", 5}},
       std::nullopt, "", 70},
      {"simulated time runs out (after the drain window)",
       {{S::kTick, "", "", 3}, {S::kLine, "physics", "t=59.9 event=tick", 0},
        {S::kLine, "physics", "t=60 event=tick", 0}, {S::kTick, "", "", 3.5}, {S::kTick, "", "", 4}},
       dsl::Outcome::kTimeout, "simulated time ran out (1m)", 60},
      {"an ending line stamped before the timeout but arriving after the clock's wins",
       {{S::kTick, "", "", 3}, {S::kLine, "physics", "t=60 event=tick", 0},
        {S::kTick, "", "", 3.5}, {S::kLine, "scout_1", "t=15 event=mission_complete", 0},
        {S::kTick, "", "", 9}},
       dsl::Outcome::kSuccess, "matched 'event=mission_complete'", 60},
      {"the clock component stopping at the timeout confirms it at once",
       {{S::kLine, "physics", "t=60 event=stopped", 0}, {S::kExit, "physics", "", 0}},
       dsl::Outcome::kTimeout, "simulated time ran out (1m)", 60},
      {"a crash ends it",
       {{S::kLine, "physics", "t=3 event=tick", 0}, {S::kExit, "scout_1", "", 139}},
       dsl::Outcome::kFailure, "scout_1 exited with code 139 before the trial ended", 3},
      {"wall guard",
       {{S::kLine, "physics", "t=3 event=tick", 0}, {S::kTick, "", "", 119}, {S::kTick, "", "", 120}},
       dsl::Outcome::kError, "wall-clock guard: 2m passed with simulated time at 3.0s of 1m", 3},
      {"the first end wins",
       {{S::kLine, "scout_1", "t=3 event=collision", 0}, {S::kLine, "scout_1", "t=4 event=mission_complete", 0},
        {S::kExit, "physics", "", 1}, {S::kTick, "", "", 500}},
       dsl::Outcome::kFailure, "collision", 3},
  };
  for (const Scenario& sc : scenarios) {
    SCOPED_TRACE(sc.name);
    auto trial = MakeTrial();
    auto m = Monitor::Create(*trial);
    ASSERT_TRUE(m);
    m->Started("physics");
    m->Started("scout_1");
    std::optional<dsl::Verdict> first;
    for (const Step& s : sc.steps) {
      std::optional<dsl::Verdict> v;
      if (s.kind == Step::kLine) v = m->OnLine(s.component, s.text);
      if (s.kind == Step::kExit) v = m->OnExit(s.component, static_cast<std::int64_t>(s.value), false);
      if (s.kind == Step::kTick) v = m->OnTick(s.value);
      if (v) {
        EXPECT_FALSE(first.has_value()) << "a second end was reported: " << v->ToString();
        first = v;
      }
    }
    ASSERT_EQ(first.has_value(), sc.outcome.has_value());
    if (first) {
      EXPECT_EQ(first->outcome, *sc.outcome);
      EXPECT_EQ(first->reason, sc.reason);
    }
    EXPECT_DOUBLE_EQ(m->sim_s(), sc.sim_s);
  }
}

TEST(Monitor, ProgressLineShowsClocksMissionStateAndLiveComponents) {
  auto trial = MakeTrial();
  auto m = Monitor::Create(*trial);
  ASSERT_TRUE(m);
  m->Started("physics");
  m->Started("scout_1");
  (void)m->OnLine("physics", "t=10.000 node=physics event=clock rtf=0.97 steps=2500 late=0 lost=0");
  (void)m->OnLine("scout_1", "t=12.500 node=scout_1 event=leader_elected term=1 leader=scout_1");
  (void)m->OnLine("scout_1", "t=12.500 node=scout_1 event=link peer=scout_2 sent=10 received=10 loss=0.0000");
  (void)m->OnTick(13.04);
  // The folded state (trial_progress.hpp), not the last events (mostly `link`).
  EXPECT_EQ(m->ProgressLine(), "sim 12.5/60.0s  rtf 0.97  wall 13.0s  leader scout_1  live 2/2");
  (void)m->OnExit("scout_1", 0, true);
  EXPECT_EQ(m->live().size(), 1u);
  EXPECT_EQ(m->verdict()->reason, "scout_1 was killed for lack of memory");
}

}  // namespace
}  // namespace swarmbox::runner

namespace swarmbox::runner {
namespace {

// Exit rules (issue #24): a brain may leave at any time (its drone's offboard failsafe answers), a
// user component may finish with 0; anything else leaving, or an OOM kill, still ends the trial.
TEST(Monitor, ExitRulesLetBrainsGoAndComponentsFinish) {
  auto trial = MakeTrial();
  auto m = Monitor::Create(*trial);
  ASSERT_TRUE(m);
  for (const char* c : {"physics", "scout_1", "scout_1-brain", "ground", "recorder"}) m->Started(c);
  m->SetExitRule("scout_1-brain", Monitor::ExitRule::kAnyExitAllowed);
  m->SetExitRule("ground", Monitor::ExitRule::kCleanExitAllowed);
  m->SetExitRule("recorder", Monitor::ExitRule::kCleanExitAllowed);
  EXPECT_FALSE(m->OnExit("scout_1-brain", 137, false).has_value());
  EXPECT_FALSE(m->OnExit("ground", 0, false).has_value());
  EXPECT_EQ(m->live().count("scout_1-brain"), 0u);  // no longer live, the trial goes on
  EXPECT_FALSE(m->ended());
  auto v = m->OnExit("recorder", 2, false);
  ASSERT_TRUE(v.has_value());
  EXPECT_EQ(v->outcome, dsl::Outcome::kFailure);
  EXPECT_EQ(v->reason, "recorder exited with code 2 before the trial ended");
}

TEST(Monitor, AnOomKillEndsTheTrialWhateverTheRule) {
  auto trial = MakeTrial();
  auto m = Monitor::Create(*trial);
  ASSERT_TRUE(m);
  m->Started("scout_1-brain");
  m->SetExitRule("scout_1-brain", Monitor::ExitRule::kAnyExitAllowed);
  auto v = m->OnExit("scout_1-brain", 137, true);
  ASSERT_TRUE(v.has_value());
  EXPECT_EQ(v->reason, "scout_1-brain was killed for lack of memory");
}

}  // namespace
}  // namespace swarmbox::runner
