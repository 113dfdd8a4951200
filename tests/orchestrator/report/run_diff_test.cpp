// report::DiffRuns (pure): the first divergence between two runs' truth.csv, events.jsonl and
// result.json, as `swarmbox diff` prints it.
#include "swarmbox/report/run_diff.hpp"

#include <gtest/gtest.h>

#include <string>

namespace swarmbox::report {
namespace {

constexpr char kHeader[] = "t_s,drone,x_m,y_m,z_m\n";

std::string Truth(const std::string& rows) { return kHeader + rows; }

// Two drones, three steps; `change` edits one cell of the given line afterwards.
std::string ThreeSteps() {
  return Truth(
      "0.004,scout_1,0.0000,0.0000,0.1000\n"
      "0.004,scout_2,5.0000,0.0000,0.1000\n"
      "0.008,scout_1,0.0000,0.0000,0.2000\n"
      "0.008,scout_2,5.0000,0.0000,0.2000\n"
      "0.012,scout_1,0.0000,0.0000,0.3000\n"
      "0.012,scout_2,5.0000,0.0000,0.3000\n");
}

std::string Result(const std::string& outcome, const std::string& reason, const std::string& run_id,
                   const std::string& ending_line = "", const std::string& seed = "7") {
  return R"({"trial":"sar-search","outcome":")" + outcome + R"(","reason":")" + reason +
         R"(","wall_s":12.5,"sim_s":60.004,"seed":)" + seed + R"(,"run_id":")" + run_id +
         R"(","ending_line":")" + ending_line + "\"}\n";
}

RunFiles Files(std::optional<std::string> truth, std::optional<std::string> events,
               std::optional<std::string> result) {
  return RunFiles{std::move(truth), std::move(events), std::move(result)};
}

RunDiff Diff(const RunFiles& a, const RunFiles& b) {
  auto d = DiffRuns(a, b);
  EXPECT_TRUE(static_cast<bool>(d)) << (d ? "" : d.error().ToString());
  return d ? *d : RunDiff{};
}

TEST(RunDiff, IdenticalFilesAreIdentical) {
  const std::string events =
      R"({"wall_s":0.1,"component":"orchestrator","event":"build","target":"physics","outcome":"success"})"
      "\n"
      R"({"wall_s":1.2,"component":"scout_1","t":0.004,"node":"scout_1","event":"ready"})"
      "\n";
  const RunDiff d = Diff(Files(ThreeSteps(), events, Result("timeout", "simulated time ran out (60s)", "r1")),
                         Files(ThreeSteps(), events, Result("timeout", "simulated time ran out (60s)", "r1")));
  EXPECT_TRUE(d.identical());
  EXPECT_EQ(d.truth_rows, 6u);
  EXPECT_EQ(d.event_count, 2u);
  EXPECT_EQ(d.streams, 2u);
  EXPECT_FALSE(d.first_file().has_value());
  EXPECT_EQ(FormatRunDiff(d, "runs/a", "runs/b").substr(0, 36), "identical: A runs/a, B runs/b\ncompar");
}

TEST(RunDiff, TruthFirstDifferingRowNamesTimeDroneAndEachField) {
  std::string b = ThreeSteps();
  // Line 5 (0.008, scout_2): x and z differ.
  b.replace(b.find("0.008,scout_2,5.0000,0.0000,0.2000"), 34, "0.008,scout_2,5.0001,0.0000,0.2500");
  // A later row differs too: only the first is reported.
  b.replace(b.find("0.012,scout_1,0.0000"), 20, "0.012,scout_1,9.0000");
  const RunDiff d = Diff(Files(ThreeSteps(), std::nullopt, std::nullopt),
                         Files(b, std::nullopt, std::nullopt));
  ASSERT_TRUE(d.truth.has_value());
  EXPECT_EQ(d.truth->line, 5u);
  ASSERT_TRUE(d.truth->t_s.has_value());
  EXPECT_DOUBLE_EQ(*d.truth->t_s, 0.008);
  EXPECT_EQ(d.truth->drone, "scout_2");
  ASSERT_EQ(d.truth->fields.size(), 2u);
  EXPECT_EQ(d.truth->fields[0].field, "x_m");
  EXPECT_EQ(d.truth->fields[0].a, "5.0000");
  EXPECT_EQ(d.truth->fields[0].b, "5.0001");
  EXPECT_EQ(d.truth->fields[1].field, "z_m");
  EXPECT_EQ(d.truth_rows, 3u);
  EXPECT_EQ(d.first_file(), "truth.csv");
  const std::string text = FormatRunDiff(d, "A", "B");
  EXPECT_NE(text.find("first divergence in truth.csv at t=0.008 s"), std::string::npos) << text;
  EXPECT_NE(text.find("truth.csv line 5, t=0.008 s, drone scout_2:"), std::string::npos) << text;
  EXPECT_NE(text.find("x_m: 5.0000 (A)  vs  5.0001 (B)"), std::string::npos) << text;
}

TEST(RunDiff, TruthShorterFileSaysWhichEndedFirst) {
  std::string a = ThreeSteps();
  a.resize(a.find("0.012,scout_1"));  // A stops after 0.008
  const RunDiff d = Diff(Files(a, std::nullopt, std::nullopt), Files(ThreeSteps(), std::nullopt, std::nullopt));
  ASSERT_TRUE(d.truth.has_value());
  EXPECT_EQ(d.truth->ended, Side::kA);
  EXPECT_EQ(d.truth->line, 6u);
  EXPECT_DOUBLE_EQ(d.truth->t_s.value_or(-1), 0.012);
  EXPECT_EQ(d.truth->drone, "scout_1");
  EXPECT_TRUE(d.truth->fields.empty());
  EXPECT_NE(FormatRunDiff(d, "A", "B").find("run A's file ended first"), std::string::npos);
}

TEST(RunDiff, TruthDifferentHeadersAreTheFirstDivergence) {
  const RunDiff d = Diff(Files(ThreeSteps(), std::nullopt, std::nullopt),
                         Files("t_s,drone,x_m,y_m\n0.004,scout_1,0,0\n", std::nullopt, std::nullopt));
  ASSERT_TRUE(d.truth.has_value());
  EXPECT_EQ(d.truth->line, 1u);
  ASSERT_EQ(d.truth->fields.size(), 1u);
  EXPECT_EQ(d.truth->fields[0].field, "column 5");
  EXPECT_EQ(d.truth->fields[0].a, "z_m");
  EXPECT_FALSE(d.truth->fields[0].b.has_value());
}

TEST(RunDiff, TruthWithoutTimeOrDroneColumnIsAnError) {
  auto d = DiffRuns(Files("a,b\n1,2\n", std::nullopt, std::nullopt), Files(ThreeSteps(), std::nullopt, std::nullopt));
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(d.error().ToString().find("truth.csv of run A:1"), std::string::npos) << d.error().ToString();
  EXPECT_NE(d.error().ToString().find("no t_s or drone column"), std::string::npos);
}

TEST(RunDiff, EventsDifferingOnlyInWallClockFieldsAreIdentical) {
  const std::string a =
      R"({"wall_s":0.2,"component":"orchestrator","event":"run","target":"physics","outcome":"success"})" "\n"
      R"({"wall_s":3.1,"component":"physics","t":0,"node":"physics","event":"ready","rtf":0.00,"seed":7})" "\n"
      R"({"wall_s":5.0,"component":"physics","t":10.000,"node":"physics","event":"clock","rtf":3.73,"steps":2500,"late":0,"lost":0})" "\n"
      R"({"type":"fault","phase":"applied","fault":"kill","t_sim_s":30.0,"wall_s":8.1,"requested_wall_s":8.0,"targets":["scout_2"]})" "\n"
      R"({"type":"mechanism","host":"box-1","mechanism":"userspace-nfqueue","detected":"true","wall_s":0.1})" "\n"
      R"({"wall_s":9.9,"component":"scout_1","t":12.5,"node":"scout_1","event":"ping","sent_wall_ns":123,"wall_ms":4})" "\n";
  // B: other wall times, another pace (rtf 1 asked, 0.98 achieved, late steps), another host and
  // cache state, and the lines of different writers interleaved in another wall-clock order.
  const std::string b =
      R"({"type":"mechanism","host":"box-2","mechanism":"userspace-nfqueue","detected":"false","wall_s":0.3})" "\n"
      R"({"wall_s":2.0,"component":"physics","t":0,"node":"physics","event":"ready","rtf":1.00,"seed":7})" "\n"
      R"({"wall_s":2.4,"component":"orchestrator","event":"run","target":"physics","outcome":"success"})" "\n"
      R"({"wall_s":11.0,"component":"scout_1","t":12.5,"node":"scout_1","event":"ping","sent_wall_ns":999,"wall_ms":9})" "\n"
      R"({"wall_s":10.2,"component":"physics","t":10.000,"node":"physics","event":"clock","rtf":0.98,"steps":2500,"late":17,"lost":0})" "\n"
      R"({"type":"fault","phase":"applied","fault":"kill","t_sim_s":30.0,"wall_s":31.5,"requested_wall_s":30.9,"targets":["scout_2"]})" "\n";
  const RunDiff d = Diff(Files(std::nullopt, a, std::nullopt), Files(std::nullopt, b, std::nullopt));
  EXPECT_TRUE(d.identical()) << FormatRunDiff(d, "A", "B");
  EXPECT_EQ(d.event_count, 6u);
  EXPECT_EQ(d.streams, 5u);  // orchestrator:physics, physics, fault:kill, mechanism, scout_1
}

TEST(RunDiff, IgnoredFieldsAreExactlyTheWallClockOnes) {
  EXPECT_TRUE(IgnoredEventField("ready", "wall_s"));
  EXPECT_TRUE(IgnoredEventField("fault", "requested_wall_s"));
  EXPECT_TRUE(IgnoredEventField("ping", "sent_wall_ns"));
  EXPECT_TRUE(IgnoredEventField("ready", "rtf"));
  EXPECT_TRUE(IgnoredEventField("clock", "late"));
  EXPECT_TRUE(IgnoredEventField("mechanism", "detected"));
  EXPECT_TRUE(IgnoredEventField("mechanism", "host"));
  // Simulated-time and behaviour fields stay.
  EXPECT_FALSE(IgnoredEventField("link", "late"));  // late packets of the radio link
  EXPECT_FALSE(IgnoredEventField("fault", "t_sim_s"));
  EXPECT_FALSE(IgnoredEventField("clock", "steps"));
  EXPECT_FALSE(IgnoredEventField("ready", "host"));
  EXPECT_FALSE(IgnoredEventField("x", "walltime"));  // `wall` must be a whole word
  EXPECT_FALSE(IgnoredEventField("x", "firewall_s"));
}

// The physics server's start progress is on the wall clock: who had answered after each wall
// second (issue 18's event=joining / event=joined) differs between two runs of one trial.
TEST(RunDiff, TheStartsJoiningProgressIsNotCompared) {
  const std::string a =
      R"({"component":"physics","t":0.000,"node":"physics","event":"joining","joined":1,"expected":4,"missing":"scout_1,scout_2,lifter"})" "\n"
      R"({"component":"physics","t":0.000,"node":"physics","event":"joined","joined":4,"expected":4,"lost":0,"wait_s":1.2})" "\n"
      R"({"component":"scout_1","t":3.0,"node":"scout_1","event":"takeoff"})" "\n";
  const std::string b =
      R"({"component":"physics","t":0.000,"node":"physics","event":"joining","joined":0,"expected":4,"missing":"scout_1,scout_2,scout_3,lifter"})" "\n"
      R"({"component":"physics","t":0.000,"node":"physics","event":"joining","joined":3,"expected":4,"missing":"lifter"})" "\n"
      R"({"component":"scout_1","t":3.0,"node":"scout_1","event":"takeoff"})" "\n";
  const RunDiff d = Diff(Files(std::nullopt, a, std::nullopt), Files(std::nullopt, b, std::nullopt));
  EXPECT_TRUE(d.identical()) << FormatRunDiff(d, "A", "B");
  EXPECT_EQ(d.event_count, 1u);
  // Any other event of the start still counts.
  const std::string c = b + R"({"component":"physics","t":0.000,"node":"physics","event":"drone_lost","drone":"lifter"})" "\n";
  EXPECT_FALSE(Diff(Files(std::nullopt, a, std::nullopt), Files(std::nullopt, c, std::nullopt)).identical());
}

TEST(RunDiff, RunIdInValuesIsNotADifference) {
  const std::string a =
      R"({"wall_s":1,"component":"orchestrator","event":"stop","target":"scout_1","outcome":"failure","reason":"swarmbox-20261126-1-scout_1 exited"})" "\n";
  const std::string b =
      R"({"wall_s":1,"component":"orchestrator","event":"stop","target":"scout_1","outcome":"failure","reason":"swarmbox-20261126-2-scout_1 exited"})" "\n";
  const RunDiff d = Diff(Files(std::nullopt, a, Result("failure", "swarmbox-20261126-1-scout_1 exited", "20261126-1")),
                         Files(std::nullopt, b, Result("failure", "swarmbox-20261126-2-scout_1 exited", "20261126-2")));
  EXPECT_TRUE(d.identical()) << FormatRunDiff(d, "A", "B");
}

TEST(RunDiff, EventsEarliestDivergenceBySimulatedTimeAcrossStreams) {
  // scout_2's stream diverges at line 4 of the file (t=9.5), scout_1's later in the file but
  // earlier in simulated time (t=8.48): the report is scout_1's.
  const std::string a =
      R"({"wall_s":1,"component":"scout_2","t":1.0,"node":"scout_2","event":"takeoff"})" "\n"
      R"({"wall_s":1,"component":"scout_1","t":1.0,"node":"scout_1","event":"takeoff"})" "\n"
      R"({"wall_s":2,"component":"scout_2","t":9.5,"node":"scout_2","event":"mode","mode":"SEARCH"})" "\n"
      R"({"wall_s":3,"component":"scout_1","t":8.48,"node":"scout_1","event":"leader_elected","term":2,"leader":"scout_1"})" "\n";
  const std::string b =
      R"({"wall_s":1,"component":"scout_1","t":1.0,"node":"scout_1","event":"takeoff"})" "\n"
      R"({"wall_s":1,"component":"scout_2","t":1.0,"node":"scout_2","event":"takeoff"})" "\n"
      R"({"wall_s":2,"component":"scout_2","t":9.5,"node":"scout_2","event":"mode","mode":"HOLD"})" "\n"
      R"({"wall_s":3,"component":"scout_1","t":8.52,"node":"scout_1","event":"leader_elected","term":2,"leader":"scout_1"})" "\n";
  const RunDiff d = Diff(Files(std::nullopt, a, std::nullopt), Files(std::nullopt, b, std::nullopt));
  ASSERT_TRUE(d.events.has_value());
  EXPECT_EQ(d.events->stream, "scout_1");
  EXPECT_DOUBLE_EQ(d.events->t_s.value_or(-1), 8.48);
  EXPECT_EQ(d.events->line_a, 4u);
  EXPECT_EQ(d.events->line_b, 4u);
  EXPECT_EQ(d.events->index, 1u);
  ASSERT_EQ(d.events->fields.size(), 1u);
  EXPECT_EQ(d.events->fields[0].field, "t");
  EXPECT_EQ(d.events->fields[0].a, "8.48");
  EXPECT_EQ(d.events->fields[0].b, "8.52");
  EXPECT_EQ(d.events->event_a, R"({"component":"scout_1","t":8.48,"node":"scout_1","event":"leader_elected","term":2,"leader":"scout_1"})");
  const std::string text = FormatRunDiff(d, "A", "B");
  EXPECT_NE(text.find("events.jsonl stream scout_1, event 2, t=8.480 s (line 4 of A, line 4 of B)"),
            std::string::npos) << text;
}

TEST(RunDiff, EventsStreamEndingEarlyIsADivergence) {
  const std::string a =
      R"({"wall_s":1,"component":"lifter","t":1.0,"node":"lifter","event":"takeoff"})" "\n"
      R"({"wall_s":1,"component":"lifter","t":2.0,"node":"lifter","event":"hover"})" "\n";
  const std::string b = R"({"wall_s":1,"component":"lifter","t":1.0,"node":"lifter","event":"takeoff"})" "\n";
  const RunDiff d = Diff(Files(std::nullopt, a, std::nullopt), Files(std::nullopt, b, std::nullopt));
  ASSERT_TRUE(d.events.has_value());
  EXPECT_EQ(d.events->line_a, 2u);
  EXPECT_EQ(d.events->line_b, 0u);
  EXPECT_TRUE(d.events->event_b.empty());
  EXPECT_DOUBLE_EQ(d.events->t_s.value_or(-1), 2.0);
  EXPECT_NE(FormatRunDiff(d, "A", "B").find("B: (the stream ended)"), std::string::npos);
}

TEST(RunDiff, UntimedDivergenceComesAfterTimedOnes) {
  // The orchestrator's lifecycle records carry no simulated time: a difference there ranks after
  // a timed one, wherever it is in the file.
  const std::string a =
      R"({"wall_s":1,"component":"orchestrator","event":"stop","target":"scout_1","outcome":"success"})" "\n"
      R"({"wall_s":1,"component":"scout_1","t":3.0,"node":"scout_1","event":"hover"})" "\n";
  const std::string b =
      R"({"wall_s":1,"component":"orchestrator","event":"stop","target":"scout_1","outcome":"failure"})" "\n"
      R"({"wall_s":1,"component":"scout_1","t":3.0,"node":"scout_1","event":"land"})" "\n";
  const RunDiff d = Diff(Files(std::nullopt, a, std::nullopt), Files(std::nullopt, b, std::nullopt));
  ASSERT_TRUE(d.events.has_value());
  EXPECT_EQ(d.events->stream, "scout_1");
}

TEST(RunDiff, MalformedEventLineIsAnErrorWithItsLine) {
  auto d = DiffRuns(Files(std::nullopt, "{\"t\":1}\nnot json {\n", std::nullopt),
                    Files(std::nullopt, "{\"t\":1}\n", std::nullopt));
  ASSERT_FALSE(d);
  EXPECT_NE(d.error().ToString().find("events.jsonl of run A:2"), std::string::npos) << d.error().ToString();
}

TEST(RunDiff, ResultOutcomeAndReasonNotWallTimes) {
  const RunDiff same = Diff(Files(std::nullopt, std::nullopt, Result("success", "matched 'event=mission_complete'", "r1")),
                            Files(std::nullopt, std::nullopt, R"({"outcome":"success","reason":"matched 'event=mission_complete'","wall_s":99,"sim_s":300.1,"run_id":"r2","seed":7,"trial":"sar-search"})"));
  EXPECT_TRUE(same.identical()) << FormatRunDiff(same, "A", "B");
  const RunDiff d = Diff(Files(std::nullopt, std::nullopt, Result("success", "matched 'event=mission_complete'", "r1")),
                         Files(std::nullopt, std::nullopt, Result("timeout", "simulated time ran out (60s)", "r2", "", "8")));
  ASSERT_TRUE(d.result.has_value());
  ASSERT_EQ(d.result->fields.size(), 2u);
  EXPECT_EQ(d.result->fields[0].field, "outcome");
  EXPECT_EQ(d.result->fields[0].b, "timeout");
  EXPECT_EQ(d.result->fields[1].field, "reason");
  ASSERT_EQ(d.notes.size(), 1u);
  EXPECT_EQ(d.notes[0], "the seeds differ: 7 (A), 8 (B)");
  EXPECT_EQ(d.first_file(), "result.json");
}

TEST(RunDiff, EndedOnALineComparesUpToThatLinesSimulatedTime) {
  // Both ended on mission_complete at t=0.008; B's physics ran on longer before its stop arrived
  // (a truth row and an event past the end): not a divergence.
  const std::string ending = "t=0.008 node=scout_1 event=mission_complete victims=2 rescued=2";
  std::string a = ThreeSteps();
  a.resize(a.find("0.012,scout_1"));
  const std::string ev_a =
      R"({"wall_s":1,"component":"scout_1","t":0.008,"node":"scout_1","event":"mission_complete","victims":2,"rescued":2})" "\n"
      R"({"wall_s":2,"component":"scout_1","t":0.009,"node":"scout_1","event":"stopped","reason":"signal"})" "\n";
  const std::string ev_b =
      R"({"wall_s":1,"component":"scout_1","t":0.008,"node":"scout_1","event":"mission_complete","victims":2,"rescued":2})" "\n"
      R"({"wall_s":3,"component":"scout_1","t":0.012,"node":"scout_1","event":"stopped","reason":"signal"})" "\n";
  const RunDiff d = Diff(Files(a, ev_a, Result("success", "matched 'event=mission_complete'", "r1", ending)),
                         Files(ThreeSteps(), ev_b, Result("success", "matched 'event=mission_complete'", "r2", ending)));
  EXPECT_TRUE(d.identical()) << FormatRunDiff(d, "A", "B");
  EXPECT_DOUBLE_EQ(d.horizon_s.value_or(-1), 0.008);
  EXPECT_EQ(d.truth_rows, 4u);
  EXPECT_NE(FormatRunDiff(d, "A", "B").find("up to t=0.008 s: the trial ended on"), std::string::npos);
}

TEST(RunDiff, FileInOneRunOnlyIsADivergence) {
  const RunDiff d = Diff(Files(ThreeSteps(), std::nullopt, std::nullopt), Files(std::nullopt, std::nullopt, std::nullopt));
  ASSERT_EQ(d.missing.size(), 1u);
  EXPECT_EQ(d.missing[0].file, "truth.csv");
  EXPECT_EQ(d.missing[0].missing_in, Side::kB);
  EXPECT_FALSE(d.identical());
  EXPECT_NE(FormatRunDiff(d, "A", "B").find("truth.csv: not in run B"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::report
