// `swarmbox diff RUN_A RUN_B` in process, on trial folders written here: exit 0 identical (also
// when only wall-clock fields differ), 1 with the first divergence, 2 for what is not a trial
// folder; --json.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "support/capture_streams.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::cli {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using Capture = swarmbox::testing::CaptureStreams;

constexpr char kTruth[] =
    "t_s,drone,x_m,y_m,z_m\n"
    "0.020,scout_1,0.0000,0.0000,0.5000\n"
    "0.020,scout_2,5.0000,0.0000,0.5000\n"
    "0.040,scout_1,0.0000,0.0000,1.0000\n"
    "0.040,scout_2,5.0000,0.0000,1.0000\n";

// A run's events.jsonl: `wall` offsets every wall time, `swap` writes the two agents' lines in the
// other wall-clock order, `rtf` is the pace asked for.
std::string Events(double wall, bool swap, const std::string& rtf, const std::string& run_id) {
  auto w = [&](double s) { return std::to_string(s + wall); };
  const std::string s1 = R"({"wall_s":)" + w(2) +
                         R"(,"component":"scout_1","t":0.02,"node":"scout_1","event":"takeoff"})" "\n";
  const std::string s2 = R"({"wall_s":)" + w(2.1) +
                         R"(,"component":"scout_2","t":0.02,"node":"scout_2","event":"takeoff"})" "\n";
  return R"({"wall_s":)" + w(0.1) +
         R"(,"component":"orchestrator","event":"run","target":"physics","outcome":"success"})" "\n" +
         R"({"wall_s":)" + w(1) + R"(,"component":"physics","t":0,"node":"physics","event":"ready","rtf":)" +
         rtf + R"(,"truth":"/swarmbox/out/truth.csv"})" "\n" + (swap ? s2 + s1 : s1 + s2) +
         R"({"wall_s":)" + w(3) +
         R"(,"component":"orchestrator","event":"stop","target":"physics","outcome":"success","reason":"container swarmbox-)" +
         run_id + R"(-physics stopped"})" "\n";
}

std::string Result(const std::string& run_id, double wall_s, const std::string& seed = "7") {
  return R"x({"trial":"two","outcome":"timeout","reason":"simulated time ran out (0.04s)","wall_s":)x" +
         std::to_string(wall_s) + R"(,"sim_s":0.04,"seed":)" + seed + R"(,"run_id":")" + run_id +
         R"(","ending_line":""})" "\n";
}

class DiffCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scratch_ = fs::temp_directory_path() / ("swarmbox-cli-diff-" + std::to_string(::getpid()));
    fs::create_directories(scratch_);
  }
  void TearDown() override { fs::remove_all(scratch_); }

  std::string WriteRun(const std::string& name, const std::string& truth, const std::string& events,
                       const std::string& result) {
    const fs::path dir = scratch_ / name;
    fs::create_directories(dir);
    std::ofstream(dir / "truth.csv") << truth;
    std::ofstream(dir / "events.jsonl") << events;
    std::ofstream(dir / "result.json") << result;
    return dir.string();
  }

  fs::path scratch_;
};

TEST_F(DiffCommandTest, IdenticalRunsExit0) {
  const std::string a = WriteRun("a", kTruth, Events(0, false, "0.00", "r1"), Result("r1", 1.5));
  const std::string b = WriteRun("b", kTruth, Events(0, false, "0.00", "r1"), Result("r1", 1.5));
  Capture c;
  EXPECT_EQ(DiffCommand({a, b, false}), kExitOk);
  EXPECT_THAT(c.out(), HasSubstr("identical: A " + a + ", B " + b));
  EXPECT_THAT(c.out(), HasSubstr("truth.csv (4 rows alike) events.jsonl (5 events in 4 streams) result.json"));
}

TEST_F(DiffCommandTest, RunsDifferingOnlyInWallClockFieldsExit0) {
  // Other wall times, the agents' lines in the other wall-clock order, rtf 1 instead of 0, another
  // run id (in result.json and inside a container name), another wall_s in result.json.
  const std::string a = WriteRun("a", kTruth, Events(0, false, "0.00", "20261126-0100-aaaa"),
                                 Result("20261126-0100-aaaa", 1.5));
  const std::string b = WriteRun("b", kTruth, Events(7.25, true, "1.00", "20261126-0200-bbbb"),
                                 Result("20261126-0200-bbbb", 9.75));
  Capture c;
  EXPECT_EQ(DiffCommand({a, b, false}), kExitOk) << c.out();
  EXPECT_THAT(c.out(), HasSubstr("identical"));
}

TEST_F(DiffCommandTest, DifferentTruthExit1WithTheFirstDivergence) {
  std::string truth_b = kTruth;
  truth_b.replace(truth_b.find("0.040,scout_2,5.0000"), 20, "0.040,scout_2,5.0125");
  const std::string a = WriteRun("a", kTruth, Events(0, false, "0.00", "r1"), Result("r1", 1.5));
  const std::string b = WriteRun("b", truth_b, Events(0, false, "0.00", "r2"), Result("r2", 1.5, "8"));
  Capture c;
  EXPECT_EQ(DiffCommand({a, b, false}), kExitOutcome);
  EXPECT_THAT(c.out(), HasSubstr("first divergence in truth.csv at t=0.040 s"));
  EXPECT_THAT(c.out(), HasSubstr("truth.csv line 5, t=0.040 s, drone scout_2:\n  x_m: 5.0000 (A)  vs  5.0125 (B)"));
  EXPECT_THAT(c.out(), HasSubstr("note: the seeds differ: 7 (A), 8 (B)"));
}

TEST_F(DiffCommandTest, DifferentEventExit1) {
  std::string events_b = Events(0, false, "0.00", "r1");
  events_b.replace(events_b.find(R"("node":"scout_2","event":"takeoff")"), 34, R"("node":"scout_2","event":"abort")");
  const std::string a = WriteRun("a", kTruth, Events(0, false, "0.00", "r1"), Result("r1", 1.5));
  const std::string b = WriteRun("b", kTruth, events_b, Result("r1", 1.5));
  Capture c;
  EXPECT_EQ(DiffCommand({a, b, false}), kExitOutcome);
  EXPECT_THAT(c.out(), HasSubstr("events.jsonl stream scout_2, event 1, t=0.020 s (line 4 of A, line 4 of B)"));
  EXPECT_THAT(c.out(), HasSubstr("  event: takeoff (A)  vs  abort (B)"));
}

TEST_F(DiffCommandTest, JsonSaysWhereAndBothValues) {
  std::string truth_b = kTruth;
  truth_b.replace(truth_b.find("0.040,scout_1,0.0000,0.0000,1.0000"), 34, "0.040,scout_1,0.0000,0.0000,1.0100");
  const std::string a = WriteRun("a", kTruth, Events(0, false, "0.00", "r1"), Result("r1", 1.5));
  const std::string b = WriteRun("b", truth_b, Events(0, false, "0.00", "r1"), Result("r1", 1.5));
  Capture c;
  EXPECT_EQ(DiffCommand({a, b, true}), kExitOutcome);
  auto doc = yaml::Parse(c.out(), "diff --json");
  ASSERT_TRUE(doc) << doc.error().ToString() << "\n" << c.out();
  EXPECT_EQ(doc->Find("identical")->scalar(), "false");
  EXPECT_EQ(doc->Find("first_file")->scalar(), "truth.csv");
  EXPECT_EQ(doc->Find("first_t_s")->scalar(), "0.04");
  EXPECT_EQ(doc->Find("exit_code")->scalar(), "1");
  const yaml::Node* truth = doc->Find("truth");
  ASSERT_NE(truth, nullptr);
  EXPECT_EQ(truth->Find("line")->scalar(), "4");
  EXPECT_EQ(truth->Find("drone")->scalar(), "scout_1");
  const auto& fields = truth->Find("fields")->items();
  ASSERT_EQ(fields.size(), 1u);
  EXPECT_EQ(fields[0].Find("field")->scalar(), "z_m");
  EXPECT_EQ(fields[0].Find("a")->scalar(), "1.0000");
  EXPECT_EQ(fields[0].Find("b")->scalar(), "1.0100");
  EXPECT_TRUE(doc->Find("events_divergence")->is_null());
  EXPECT_TRUE(doc->Find("result")->is_null());
}

TEST_F(DiffCommandTest, NotATrialFolderIsExit2) {
  const std::string a = WriteRun("a", kTruth, Events(0, false, "0.00", "r1"), Result("r1", 1.5));
  {
    Capture c;
    EXPECT_EQ(DiffCommand({a, (scratch_ / "missing").string(), false}), kExitUsage);
    EXPECT_THAT(c.err(), HasSubstr("not a folder"));
  }
  fs::create_directories(scratch_ / "empty");
  {
    Capture c;
    EXPECT_EQ(DiffCommand({(scratch_ / "empty").string(), a, false}), kExitUsage);
    EXPECT_THAT(c.err(), HasSubstr("not a trial folder (no truth.csv, events.jsonl or result.json)"));
  }
}

TEST_F(DiffCommandTest, UnparsableFileIsExit2WithFileAndLine) {
  const std::string a = WriteRun("a", kTruth, Events(0, false, "0.00", "r1"), Result("r1", 1.5));
  const std::string b = WriteRun("b", kTruth, Events(0, false, "0.00", "r1") + "{\"cut\": \n", Result("r1", 1.5));
  Capture c;
  EXPECT_EQ(DiffCommand({a, b, false}), kExitUsage);
  EXPECT_THAT(c.err(), HasSubstr("events.jsonl of run B:6"));
}

}  // namespace
}  // namespace swarmbox::cli
