// The subcommands in process: exit codes of the CLI contract and what they print.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "experiment_check.hpp"
#include "support/capture_streams.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::cli {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using Capture = swarmbox::testing::CaptureStreams;

const std::string kTrials = std::string(SWARMBOX_SOURCE_DIR) + "/trials";

TEST(ValidateCommand, ShippedTrialsAreValid) {
  Capture c;
  EXPECT_EQ(ValidateCommand({{kTrials + "/sar_search.yaml", kTrials + "/smoke.yaml", kTrials + "/swarm_100.yaml",
                               kTrials + "/experiments/swarm_size.yaml"},
                              {}}),
            kExitOk);
  EXPECT_THAT(c.out(), HasSubstr("sar_search.yaml: ok (trial sar-search, 4 drones"));
  // A group is counted expanded.
  EXPECT_THAT(c.out(), HasSubstr("swarm_100.yaml: ok (trial swarm-100, 101 drones (scout x100), 3 end conditions"));
  EXPECT_THAT(c.out(), HasSubstr("swarm_size.yaml: ok (experiment swarm_size, 5 trials"));
}

TEST(ValidateCommand, BadFilesGiveFileLineColumnAndExit2) {
  const fs::path bad = fs::temp_directory_path() / "swarmbox-cli-bad-trial.yaml";
  {
    std::ofstream f(bad);
    f << "name: bad\nworld: worlds/open_field.yaml\ndrones:\n  - {name: a, airframe: x500}\n"
         "faults:\n  - {at: 3s, explode: a}\ntimeout: {sim: 10s}\n";
  }
  Capture c;
  ValidateArgs args{{bad.string(), kTrials + "/smoke.yaml"}, {}};
  EXPECT_EQ(ValidateCommand(args), kExitUsage);
  fs::remove(bad);
  // The bad file is reported, and the good one after it is still checked.
  EXPECT_THAT(c.err(), HasSubstr(bad.string() + ":6:14: unknown key 'explode' in fault"));
  EXPECT_THAT(c.out(), HasSubstr("smoke.yaml: ok"));
}

TEST(ValidateCommand, OverridesAreCheckedToo) {
  Capture c;
  EXPECT_EQ(ValidateCommand({{kTrials + "/smoke.yaml"}, {"physics.rtf=-1"}}), kExitUsage);
  EXPECT_THAT(c.err(), HasSubstr("'rtf' must be >= 0"));
}

// Writes `text` to a temporary file and removes it when the test ends.
class TempFile {
 public:
  TempFile(const std::string& name, const std::string& text)
      : path_(fs::temp_directory_path() / ("swarmbox-cli-" + std::to_string(::getpid()) + "-" + name)) {
    std::ofstream(path_) << text;
  }
  ~TempFile() { fs::remove(path_); }
  std::string path() const { return path_.string(); }

 private:
  fs::path path_;
};

TEST(ValidateCommand, ExperimentsAreCheckedWithEveryTrialTheyExpandTo) {
  Capture c;
  ValidateArgs args{{kTrials + "/smoke.yaml", kTrials + "/experiments/hover_grid.yaml",
                     kTrials + "/experiments/radio.yaml"},
                    {}};
  EXPECT_EQ(ValidateCommand(args), kExitOk) << c.err();
  EXPECT_THAT(c.out(), HasSubstr("hover_grid.yaml: ok (experiment hover, 8 trials of "));
  EXPECT_THAT(c.out(), HasSubstr("radio.yaml: ok (experiment radio, "));
  EXPECT_EQ(c.err(), "");
}

TEST(ValidateCommand, ALevelErrorPointsAtTheExperimentsLine) {
  // Level b of the factor sets a value the trial schema refuses, in 2 of the 4 trials.
  const TempFile exp("bad-level.yaml",
                     "name: bad\n"
                     "base: " + kTrials + "/smoke.yaml\n"
                     "set:\n"
                     "  timeout.sim: 5s\n"
                     "factors:\n"
                     "  - name: rate\n"
                     "    key: physics.rtf\n"
                     "    levels: {a: 0, b: -1}\n"
                     "repetitions: 2\n");
  Capture c;
  EXPECT_EQ(ValidateCommand({{exp.path()}, {}}), kExitUsage);
  EXPECT_EQ(c.err(), exp.path() + ":8:23: 'rtf' must be >= 0 (0 = as fast as possible) (trial bad-b-r1, key physics.rtf) "
                                  "(and 1 more trial)\n");
  EXPECT_EQ(c.out(), "");
}

TEST(ValidateCommand, ASetErrorPointsAtTheSetEntryAndABaseErrorAtTheBaseTrial) {
  // A base trial with a mistake of its own, in a trials/ folder that sees the shipped worlds and
  // airframes.
  const fs::path trials = fs::temp_directory_path() / ("swarmbox-cli-" + std::to_string(::getpid())) / "trials";
  fs::create_directories(trials);
  fs::create_symlink(kTrials + "/worlds", trials / "worlds");
  fs::create_symlink(kTrials + "/airframes", trials / "airframes");
  const std::string base = (trials / "base.yaml").string();
  std::ofstream(base) << "name: base\nworld: worlds/open_field.yaml\n"
                         "drones:\n  - {name: scout_1, airframe: x500, pose: [0, 0, 0]}\n"
                         "timeout: {sim: 10s}\n"
                         "wind: strong\n";
  const TempFile exp("bad-set.yaml",
                     "name: bad\n"
                     "base: " + kTrials + "/smoke.yaml\n"
                     "set: {timeout.sim: forever}\n"
                     "factors:\n"
                     "  - {name: rate, key: physics.rtf, levels: {a: 0, b: 1}}\n");
  const TempFile on_bad_base("on-bad-base.yaml",
                             "name: bad\nbase: " + base + "\n"
                             "factors:\n  - {name: rate, key: physics.rtf, levels: {a: 0}}\n");
  Capture c;
  EXPECT_EQ(ValidateCommand({{exp.path(), on_bad_base.path()}, {}}), kExitUsage);
  EXPECT_THAT(c.err(), HasSubstr(exp.path() + ":3:20: 'sim': expected a duration"));
  EXPECT_THAT(c.err(), HasSubstr("(trial bad-a-r1, key timeout.sim) (and 1 more trial)"));
  EXPECT_THAT(c.err(), HasSubstr(base + ":6:1: unknown key 'wind'"));
  fs::remove_all(trials.parent_path());
}

TEST(ExperimentCheck, TellsExperimentsFromTrials) {
  auto experiment = yaml::Parse("name: x\nbase: a.yaml\nfactors: []\n");
  auto trial = yaml::Parse("name: x\nworld: w.yaml\ndrones: []\n");
  ASSERT_TRUE(experiment && trial);
  EXPECT_TRUE(LooksLikeExperiment(*experiment));
  EXPECT_FALSE(LooksLikeExperiment(*trial));
  EXPECT_FALSE(LooksLikeExperiment(yaml::Node::Scalar("x")));
}

TEST(ExperimentCheck, FindsTheOverrideKeyOfAnError) {
  EXPECT_EQ(OverrideKeyOf(Error(ErrorCode::kInvalidArgument, "m", "--set physics.rtf:1:1")),
            std::optional<std::string>("physics.rtf"));
  EXPECT_EQ(OverrideKeyOf(Error(ErrorCode::kInvalidArgument, "m", "--set drones.x.pose=[1]")),
            std::optional<std::string>("drones.x.pose"));
  EXPECT_FALSE(OverrideKeyOf(Error(ErrorCode::kInvalidArgument, "m", "trials/smoke.yaml:3:1")).has_value());
}

TEST(ExperimentCheck, LocatesKeylessLevelsAndLaterFactorsFirst) {
  auto doc = yaml::Parse(
      "name: x\n"
      "set: {physics.rtf: 0}\n"
      "factors:\n"
      "  - {name: f1, key: physics.rtf, levels: {a: 1, b: 2}}\n"
      "  - name: f2\n"
      "    levels:\n"
      "      a: {physics.rtf: 3, seed: 4}\n"
      "      b: {timeout.sim: 5s}\n",
      "x.yaml");
  ASSERT_TRUE(doc) << doc.error().ToString();
  experiment::PlannedTrial ab;
  ab.code = "ab";
  experiment::PlannedTrial aa;
  aa.code = "aa";
  EXPECT_EQ(LocateOverride(*doc, ab, "physics.rtf").value_or(yaml::Mark{}).ToString(), "x.yaml:4:46");  // f1 level a
  EXPECT_EQ(LocateOverride(*doc, aa, "physics.rtf").value_or(yaml::Mark{}).ToString(), "x.yaml:7:24");  // f2 wins
  EXPECT_EQ(LocateOverride(*doc, ab, "timeout.sim").value_or(yaml::Mark{}).ToString(), "x.yaml:8:24");
  EXPECT_FALSE(LocateOverride(*doc, ab, "drones").has_value());
}

TEST(ComposeCommand, WritesAComposeFileWithTheGivenImages) {
  const fs::path out = fs::temp_directory_path() / "swarmbox-cli-compose" / "sar.compose.yaml";
  fs::create_directories(out.parent_path());
  ComposeArgs args;
  args.trial = kTrials + "/sar_search.yaml";
  args.output = out.string();
  args.physics_image = "swarmbox/physics:test";
  args.agent_image = "swarmbox/agent:test";
  args.sets = {"seed=7"};
  Capture c;
  ASSERT_EQ(ComposeCommand(args), kExitOk) << c.err();
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  auto doc = yaml::Parse(text.str(), out.string());
  ASSERT_TRUE(doc) << doc.error().ToString();
  const yaml::Node* physics = doc->Find("services")->Find("physics");
  EXPECT_EQ(physics->Find("image")->scalar(), "swarmbox/physics:test");
  // Input files are relative to the compose file's folder.
  const std::string rel = fs::path(kTrials).lexically_relative(out.parent_path()).string();
  EXPECT_EQ(physics->Find("volumes")->items()[0].scalar(),
            rel + "/worlds/open_field.yaml:/swarmbox/trials/worlds/open_field.yaml:ro");
  EXPECT_THAT(text.str(), HasSubstr("--set seed=7"));
  fs::remove_all(out.parent_path());
}

TEST(ComposeCommand, BadTrialIsExit2) {
  Capture c;
  ComposeArgs args;
  args.trial = "/nonexistent.yaml";
  EXPECT_EQ(ComposeCommand(args), kExitUsage);
  EXPECT_THAT(c.err(), HasSubstr("/nonexistent.yaml: cannot open trial file"));
}

TEST(RunCommand, BadTrialIsExit2BeforeTouchingDocker) {
  Capture c;
  RunArgs args;
  args.trial = kTrials + "/smoke.yaml";
  args.sets = {"timeout.sim=forever"};
  EXPECT_EQ(RunCommand(args), kExitUsage);
  EXPECT_THAT(c.err(), HasSubstr("--set timeout.sim:1:1: 'sim': expected a duration"));
}

TEST(RunCommand, MissingProgramIsAnInfrastructureError) {
  Capture c;
  RunArgs args;
  args.trial = kTrials + "/smoke.yaml";
  args.programs.physics_bin = "/nonexistent/swarmbox-physics";
  args.quiet = true;
  // Exit 3 either way: no engine at all, or the program to pack is missing.
  EXPECT_EQ(RunCommand(args), kExitInfrastructure);
  EXPECT_FALSE(c.err().empty());
}

TEST(ExperimentCommand, SetOverridesEveryTrialAndIsCheckedBeforeTouchingDocker) {
  Capture c;
  ExperimentArgs args;
  args.experiment = kTrials + "/experiments/radio.yaml";
  args.filter = {"a?a"};
  args.sets = {"physics.rtf=-1"};
  args.quiet = true;
  EXPECT_EQ(ExperimentCommand(args), kExitUsage);
  // Reported for the first trial the filter keeps: the override reached it.
  EXPECT_THAT(c.err(), HasSubstr("trial radio-aaa-r1 (code aaa)"));
  EXPECT_THAT(c.err(), HasSubstr("'rtf' must be >= 0"));
}

}  // namespace
}  // namespace swarmbox::cli
