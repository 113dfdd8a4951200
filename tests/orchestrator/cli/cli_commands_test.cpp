// The subcommands in process: exit codes of the CLI contract and what they print.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::cli {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// Captures std::cout and std::cerr while alive.
class Capture {
 public:
  Capture() : out_old_(std::cout.rdbuf(out_.rdbuf())), err_old_(std::cerr.rdbuf(err_.rdbuf())) {}
  ~Capture() {
    std::cout.rdbuf(out_old_);
    std::cerr.rdbuf(err_old_);
  }
  std::string out() const { return out_.str(); }
  std::string err() const { return err_.str(); }

 private:
  std::ostringstream out_, err_;
  std::streambuf* out_old_;
  std::streambuf* err_old_;
};

const std::string kTrials = std::string(SWARMBOX_SOURCE_DIR) + "/trials";

TEST(ValidateCommand, ShippedTrialsAreValid) {
  Capture c;
  EXPECT_EQ(ValidateCommand({{kTrials + "/sar_search.yaml", kTrials + "/smoke.yaml"}, {}}), kExitOk);
  EXPECT_THAT(c.out(), HasSubstr("sar_search.yaml: ok (trial sar-search, 4 drones"));
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
