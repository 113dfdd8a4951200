// The built programs as a user runs them (no Docker engine needed): --version of every program,
// the help text's version and exit codes, `validate --json` on the shipped files, and $DOCKER_HOST
// values that must fail loudly instead of falling back to the local socket.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <regex>

#include "support/child_process.hpp"
#include "swarmbox/common/version.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::cli {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using swarmbox::testing::Finished;
using swarmbox::testing::RunToEnd;

const std::string kSource = SWARMBOX_SOURCE_DIR;

class CliProgramTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scratch_ = fs::temp_directory_path() / ("swarmbox-cli-program-" + std::to_string(::getpid()));
    fs::create_directories(scratch_);
  }
  void TearDown() override {
    ::unsetenv("DOCKER_HOST");
    fs::remove_all(scratch_);
  }
  Finished Run(const std::vector<std::string>& argv) {
    auto done = RunToEnd(argv, std::chrono::seconds(60), scratch_.string());
    EXPECT_TRUE(done) << done.error().ToString();
    return done ? *done : Finished{-1, "", ""};
  }
  // The commit the programs must name: HEAD of the source tree, or "unknown" outside git.
  std::string SourceCommit() {
    auto git = RunToEnd({"/usr/bin/git", "-C", kSource, "rev-parse", "--short=12", "HEAD"},
                        std::chrono::seconds(30), scratch_.string());
    if (!git || git->code != 0) return "unknown";
    std::string c = git->out;
    while (!c.empty() && (c.back() == '\n' || c.back() == '\r')) c.pop_back();
    return c;
  }
  fs::path scratch_;
};

TEST_F(CliProgramTest, EveryProgramPrintsVersionCommitAndBuildType) {
  const std::string commit = SourceCommit();
  // "<program> <version> (commit <hash>[-dirty], <build type>)"
  const std::regex line(R"(^(\S+) (\d+\.\d+\.\d+) \(commit ([0-9a-f]{12}(-dirty)?|unknown), (\S+)\)\n$)");
  const std::vector<std::pair<std::string, std::string>> programs = {
      {"swarmbox", SWARMBOX_CLI_EXE},
      {"swarmbox-physics", SWARMBOX_PHYSICS_EXE},
      {"swarmbox-agent", SWARMBOX_AGENT_EXE},
      {"swarmbox-netemd", SWARMBOX_NETEMD_EXE},
      {"swarmbox-bench", SWARMBOX_BENCH_EXE},
  };
  for (const auto& [name, exe] : programs) {
    const Finished f = Run({exe, "--version"});
    EXPECT_EQ(f.code, 0) << name << ": " << f.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_match(f.out, m, line)) << name << " printed '" << f.out << "'";
    EXPECT_EQ(m[1].str(), name);
    EXPECT_EQ(m[2].str(), std::string(Build().version)) << name;
    EXPECT_EQ(m[3].str().substr(0, commit.size()), commit) << name << ": built from another commit";
    EXPECT_EQ(m[5].str(), std::string(Build().build_type)) << name;
    EXPECT_EQ(f.out, VersionLine(name) + "\n");
  }
  // `swarmbox version --json` says the same for scripts.
  const Finished v = Run({SWARMBOX_CLI_EXE, "version", "--json"});
  ASSERT_EQ(v.code, 0) << v.err;
  auto doc = yaml::Parse(v.out, "version --json");
  ASSERT_TRUE(doc) << doc.error().ToString();
  EXPECT_EQ(doc->Find("version")->scalar(), std::string(Build().version));
  EXPECT_EQ(doc->Find("commit")->scalar(), std::string(Build().commit));
  EXPECT_EQ(doc->Find("build_type")->scalar(), std::string(Build().build_type));
}

TEST_F(CliProgramTest, HelpShowsTheVersionAndEveryExitCode) {
  const Finished f = Run({SWARMBOX_CLI_EXE, "--help"});
  EXPECT_EQ(f.code, 0) << f.err;
  EXPECT_THAT(f.out, HasSubstr(VersionLine("swarmbox")));
  for (const char* code : {"0 success", "1 another trial outcome", "2 bad input", "3 infrastructure",
                           "130", "143", "DOCKER_HOST"}) {
    EXPECT_THAT(f.out, HasSubstr(code));
  }
  // The same spellings on every subcommand: -o,--out wherever output goes, -q,--quiet, --json.
  for (const char* sub : {"run", "experiment", "compose"}) {
    EXPECT_THAT(Run({SWARMBOX_CLI_EXE, sub, "--help"}).out, HasSubstr("-o,--out")) << sub;
  }
  for (const char* sub : {"run", "experiment", "images"}) {
    EXPECT_THAT(Run({SWARMBOX_CLI_EXE, sub, "--help"}).out, HasSubstr("-q,--quiet")) << sub;
  }
  for (const char* sub : {"run", "experiment", "images", "validate", "gc", "diff"}) {
    EXPECT_THAT(Run({SWARMBOX_CLI_EXE, sub, "--help"}).out, HasSubstr("--json")) << sub;
  }
  EXPECT_THAT(Run({SWARMBOX_CLI_EXE, "gc", "--help"}).out, HasSubstr("--dry-run"));
}

TEST_F(CliProgramTest, ComposeWritesWithOutAndTheOldSpellingStillWorks) {
  for (const char* option : {"-o", "--out", "--output"}) {
    const fs::path out = scratch_ / (std::string("c") + option + ".yaml");
    const Finished f = Run({SWARMBOX_CLI_EXE, "compose", kSource + "/trials/smoke.yaml", option,
                            out.string(), "--physics-image", "p:1", "--agent-image", "a:1"});
    EXPECT_EQ(f.code, 0) << option << ": " << f.err;
    EXPECT_TRUE(fs::exists(out)) << option;
  }
}

// The README's line: every trial and experiment file validates, and --json says so per file.
TEST_F(CliProgramTest, ValidateJsonCoversTrialsAndExperiments) {
  const Finished f = Run({SWARMBOX_CLI_EXE, "validate", "--json", kSource + "/trials/smoke.yaml",
                          kSource + "/trials/faults/partition.yaml",
                          kSource + "/trials/experiments/hover_grid.yaml"});
  EXPECT_EQ(f.code, 0) << f.err;
  auto doc = yaml::Parse(f.out, "validate --json");
  ASSERT_TRUE(doc) << doc.error().ToString() << "\n" << f.out;
  EXPECT_EQ(doc->Find("ok")->scalar(), "true");
  const auto& files = doc->Find("files")->items();
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(files[0].Find("kind")->scalar(), "trial");
  EXPECT_EQ(files[0].Find("name")->scalar(), "smoke");
  EXPECT_EQ(files[2].Find("kind")->scalar(), "experiment");
  EXPECT_EQ(files[2].Find("name")->scalar(), "hover");
  EXPECT_EQ(files[2].Find("trials")->scalar(), "8");
  EXPECT_TRUE(files[2].Find("errors")->items().empty());
}

TEST_F(CliProgramTest, AnUnusableDockerHostFailsLoudlyAndNeverFallsBackToTheLocalSocket) {
  struct Case {
    const char* docker_host;
    int code;
    const char* says;
  };
  const std::vector<Case> cases = {
      {"npipe:////./pipe/docker_engine", 2, "unknown scheme 'npipe'"},
      {"localhost:2375", 2, "the scheme is missing"},
      {"ssh://me@build-box", 2, "swarmbox experiment --hosts ssh://me@build-box"},
      {"tcp://127.0.0.1:notaport", 2, "is not a number"},
      // Nothing listens on port 1: the error names the tcp endpoint, not /var/run/docker.sock.
      {"tcp://127.0.0.1:1", 3, "no Docker engine answers at tcp://127.0.0.1:1"},
  };
  for (const Case& c : cases) {
    ::setenv("DOCKER_HOST", c.docker_host, 1);
    for (const std::vector<std::string>& argv :
         {std::vector<std::string>{SWARMBOX_CLI_EXE, "gc", "--dry-run"},
          std::vector<std::string>{SWARMBOX_CLI_EXE, "images", "-q"}}) {
      const Finished f = Run(argv);
      EXPECT_EQ(f.code, c.code) << c.docker_host << " " << argv[1] << ": " << f.err;
      EXPECT_THAT(f.err, HasSubstr(c.says)) << c.docker_host << " " << argv[1];
      if (c.code == 2) {
        EXPECT_THAT(f.err, HasSubstr(std::string("DOCKER_HOST=") + c.docker_host + ": "));
      }
      EXPECT_EQ(f.err.find("answers at /var/run/docker.sock"), std::string::npos) << f.err;
      EXPECT_TRUE(f.out.empty()) << f.out;
    }
  }
}

}  // namespace
}  // namespace swarmbox::cli
