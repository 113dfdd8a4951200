// Every command line of the README's shell code blocks works (label e2e: the real Docker engine).
//
// The test reads README.md's ```sh blocks (markdown.hpp: continuations joined, comments dropped,
// words split as a shell would) and finds each command line in kRules below, by its words. A line
// is either run, as written or with the stated per-line change (appended arguments, a replaced
// word: only where the README's own line would take minutes or needs what a test host lacks), or
// excluded with the reason. A README line that is in neither, or a rule whose line is no longer in
// the README, fails the test: edit the README and this table together.
//
// The lines run in README order from argv arrays (no shell: globs such as trials/*.yaml are
// expanded by the test, as sh would), in a scratch folder holding `trials` (-> the source tree's)
// and `build` (-> this build tree), so `build/orchestrator/cli/swarmbox run trials/smoke.yaml
// --out runs` runs as a user types it and writes into the scratch folder. `run` and `experiment`
// lines get `--run-id` added, so whatever a failure leaves behind is removed by its label.
// Expected: exit 0 for every line run (a trial's `success`; for experiments, every trial reached
// an outcome).
#include <glob.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>

#include "markdown.hpp"
#include "support/child_process.hpp"
#include "support/files.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/runner/naming.hpp"

namespace swarmbox::docs {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const fs::path kSource = fs::path(SWARMBOX_SOURCE_DIR);
const fs::path kBinary = fs::path(SWARMBOX_BINARY_DIR);
constexpr char kReadme[] = "README.md";

// What the test does with one README command line.
// (Every member initialised, so the table's designated initialisers may leave any out.)
struct Rule {
  std::string line = {};                     // the command's words joined by spaces, quotes removed
  std::string excluded = {};                 // non-empty: not run, and why
  std::vector<std::string> append = {};      // arguments added at the end
  std::map<std::string, std::string> replace = {};  // a word of the line -> what runs instead
  std::string why = {};                      // why the line is changed (required when it is)
  std::chrono::seconds timeout = 120s;
  std::string stdout_has = {};               // non-empty: what stdout must contain
};

constexpr char kCli[] = "build/orchestrator/cli/swarmbox";
const std::string kShort = "timeout.sim=2s";

std::vector<Rule> Rules() {
  const std::string cli = kCli;
  return {
      {.line = "bash scripts/quickstart.sh",
       .excluded = "installs packages as root, builds, and runs the SAR trial at real time (5 minutes); "
                   "its parts are covered: the images and `run` below, SarSearchE2e"},
      {.line = "bash scripts/test.sh", .excluded = "the CI itself, which runs this test"},
      {.line = cli + " run trials/smoke.yaml --out runs", .timeout = 300s},
      {.line = cli + " run trials/sar_search.yaml --set physics.rtf=0 --set network.mesh.loss=0.1",
       .timeout = 600s},
      {.line = cli + " run trials/faults/leader_kill.yaml",
       .excluded = "4-5 minutes at real time; LeaderKillE2e (tests/orchestrator/cli) runs this line "
                   "with --set physics.rtf=0 and checks the failover and the rescue"},
      {.line = cli + " validate trials/*.yaml trials/faults/*.yaml trials/experiments/*.yaml", .timeout = 60s},
      {.line = cli + " compose trials/sar_search.yaml", .timeout = 60s, .stdout_has = "services:"},
      {.line = cli + " diff runs/RUN_A runs/RUN_B",
       .excluded = "RUN_A and RUN_B stand for two trial folders; cli_diff_command_test runs diff on folders "
                   "it writes, ReproducibleE2e (tests/e2e/reproducible) on real runs"},
      {.line = cli + " run trials/sar_search.yaml --set seed=7 --set physics.rtf=0 --out runs/a",
       .excluded = "ReproducibleE2e (tests/e2e/reproducible) runs this line with a 30 s simulated timeout "
                   "and diffs it against the rtf 1 and loaded runs"},
      {.line = cli + " run trials/sar_search.yaml --set seed=7 --set physics.rtf=1 --out runs/b",
       .excluded = "4-5 minutes at real time; ReproducibleE2e runs it cut short by a simulated timeout"},
      {.line = cli + " diff runs/a/sar-search-* runs/b/sar-search-*",
       .excluded = "needs the two runs above; ReproducibleE2e diffs its runs with this command"},
      {.line = cli + " view runs/sar-search-RUN_ID",
       .excluded = "RUN_ID stands for a trial folder, and view serves until Ctrl-C; LiveViewTest "
                   "(tests/record) runs view on a recording, loads the page in Chromium and stops it with SIGINT"},
      {.line = cli + " gc --dry-run", .timeout = 60s},  // removes nothing: says what gc would remove
      {.line = cli + " gc",
       .append = {"--run", "readme-commands-none"},
       .why = "a plain gc removes every dead run's leftovers on the engine, other tests' and users' "
              "included; here it removes only a run of its own (none)",
       .timeout = 60s},
      {.line = cli + " --version", .timeout = 30s, .stdout_has = "swarmbox "},
      {.line = "cmake --install build --prefix $HOME/.local",
       .excluded = "installs into the user's home; InstallTree (tests/install) installs into a scratch prefix and "
                   "builds examples/brains/rendezvous against it, as the next three lines do"},
      {.line = "cp -r examples/brains/rendezvous my_brain",
       .excluded = "the start of a user's own brain; InstallTree builds that folder against an install"},
      {.line = "cmake -S my_brain -B my_brain/build -G Ninja -DCMAKE_PREFIX_PATH=$HOME/.local",
       .excluded = "needs the install in the user's home; InstallTree configures the example against its prefix"},
      {.line = "cmake --build my_brain/build",
       .excluded = "needs the line above; InstallTree builds the example and loads it with the installed loader"},
      {.line = cli + " run trials/brains/rendezvous.yaml --out runs", .timeout = 300s},
      {.line = "bash scripts/setup.sh", .excluded = "installs Debian packages as root; this test runs after it"},
      {.line = "cmake --preset default && cmake --build build -j$(nproc)",
       .excluded = "builds the project: this test is part of that build"},
      {.line = "ctest --preset unit", .excluded = "the unit tests, which this suite runs itself"},
      {.line = "build/tests/bench/swarmbox-microbench", .stdout_has = "BM_ParseLogfmt"},
      {.line = "ctest --test-dir build --output-on-failure", .excluded = "the test suite itself, this test included"},
      {.line = "build/tests/bench/swarmbox-bench --help", .timeout = 30s},
      {.line = cli + " experiment trials/experiments/hover_grid.yaml --out runs/hover --hosts local?slots=2",
       .timeout = 420s},
      {.line = cli + " experiment trials/experiments/radio.yaml --out runs/radio --hosts local?slots=2 "
                     "--hosts ssh://lab@lab2?slots=4&known_hosts=/etc/swarmbox/known_hosts",
       .excluded = "needs a second host reached by ssh (TwoHostExperiment, tests/orchestrator/experiment, runs an experiment "
                   "over a second dockerd in a network namespace)"},
      {.line = cli + " experiment trials/experiments/radio.yaml --out runs/radio --resume",
       .append = {"--filter", "aab", "--set", "physics.rtf=0", "--set", kShort},
       .why = "81 SAR trials of 4-5 minutes: here the 3 repetitions of one code, ended after 2 simulated "
              "seconds (the outcome timeout still counts as an outcome)",
       .timeout = 300s},
      {.line = cli + " experiment trials/experiments/radio.yaml --out runs/radio-a --filter a??",
       .append = {"--set", "physics.rtf=0", "--set", kShort},
       .replace = {{"a??", "aa?"}},
       .why = "27 SAR trials of 4-5 minutes: here 9 (filter aa?), ended after 2 simulated seconds",
       .timeout = 420s},
      {.line = cli + " experiment trials/experiments/radio.yaml --out runs/radio-example --filter ?bb --set "
                     "physics.rtf=0 --hosts local?slots=2",
       .append = {"--set", kShort},
       .why = "9 SAR trials of about a minute each at rtf 0: here ended after 2 simulated seconds",
       .timeout = 420s},
      {.line = cli + " report runs/radio", .timeout = 60s, .stdout_has = "report.html"},
  };
}

// The words of `pattern` (a glob) in `dir`, relative as the shell leaves them; the pattern itself
// when nothing matches (sh's default).
std::vector<std::string> Expand(const std::string& pattern, const fs::path& dir) {
  const std::string prefix = dir.string() + "/";
  glob_t g{};
  std::vector<std::string> out;
  if (::glob((prefix + pattern).c_str(), 0, nullptr, &g) == 0) {
    for (std::size_t i = 0; i < g.gl_pathc; ++i) out.push_back(std::string(g.gl_pathv[i]).substr(prefix.size()));
  }
  ::globfree(&g);
  if (out.empty()) out.push_back(pattern);
  return out;
}

class ReadmeCommands : public ::testing::Test {
 protected:
  void SetUp() override {
    work_ = testing::MakeTempDir("swarmbox-readme-");
    ASSERT_FALSE(work_.empty());
    fs::create_directory_symlink(kSource / "trials", fs::path(work_) / "trials");
    fs::create_directory_symlink(kBinary, fs::path(work_) / "build");
  }
  void TearDown() override {
    if (!run_ids_.empty()) {
      auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
      ASSERT_TRUE(client) << client.error().ToString();
      for (const std::string& id : run_ids_) {
        docker::LabelSelector run;
        run.equals[std::string(docker::kLabelRun)] = id;
        auto removed = docker::RemoveLabelled(**client, run, /*include_images=*/false);
        EXPECT_TRUE(removed) << removed.error().ToString();
        if (removed) {
          EXPECT_TRUE(removed->containers.empty()) << "run " << id << " left containers behind";
        }
      }
    }
    fs::remove_all(work_);
  }

  std::string work_;
  std::vector<std::string> run_ids_;
};

TEST_F(ReadmeCommands, EveryCommandLineIsRunOrExcludedWithAReason) {
  auto commands = ShellCommandLines(testing::ReadWholeFile((kSource / kReadme).string()));
  ASSERT_TRUE(commands) << commands.error().ToString();
  ASSERT_FALSE(commands->empty()) << "no ```sh block found in " << kReadme;
  const std::vector<Rule> rules = Rules();
  std::map<std::string, bool> used;
  for (const Rule& r : rules) {
    used[r.line] = false;
    EXPECT_TRUE(r.excluded.empty() || (r.append.empty() && r.replace.empty())) << r.line;
    EXPECT_EQ(r.append.empty() && r.replace.empty(), r.why.empty()) << "a changed line says why: " << r.line;
  }

  for (const CommandLine& c : *commands) {
    const std::string key = c.Key();
    const std::string where = std::string(kReadme) + ":" + std::to_string(c.line) + ": ";
    auto rule = std::find_if(rules.begin(), rules.end(), [&](const Rule& r) { return r.line == key; });
    if (rule == rules.end()) {
      ADD_FAILURE() << where << "`" << key << "` is neither run nor excluded: add it to Rules() in "
                    << __FILE__;
      continue;
    }
    used[key] = true;
    if (!rule->excluded.empty()) {
      std::cout << where << "excluded: " << key << " (" << rule->excluded << ")\n";
      continue;
    }

    std::vector<std::string> argv;
    for (const ShellWord& w : c.words) {
      if (auto it = rule->replace.find(w.text); it != rule->replace.end()) {
        argv.push_back(it->second);
      } else if (w.glob) {
        for (std::string& e : Expand(w.text, work_)) argv.push_back(std::move(e));
      } else {
        argv.push_back(w.text);
      }
    }
    argv.insert(argv.end(), rule->append.begin(), rule->append.end());
    if (argv.size() > 1 && argv[0] == kCli && (argv[1] == "run" || argv[1] == "experiment")) {
      run_ids_.push_back(runner::NewRunId());
      argv.insert(argv.end(), {"--run-id", run_ids_.back()});
    }
    std::string shown;
    for (const std::string& a : argv) shown += (shown.empty() ? "" : " ") + a;
    std::cout << where << "running: " << shown << (rule->why.empty() ? "" : "   (" + rule->why + ")") << std::endl;

    const std::string out = work_ + "/line-" + std::to_string(c.line) + ".out";
    const std::string err = work_ + "/line-" + std::to_string(c.line) + ".err";
    testing::SpawnOptions options;
    options.stdout_path = out;
    options.stderr_path = err;
    options.working_dir = work_;
    const auto start = std::chrono::steady_clock::now();
    auto child = testing::ChildProcess::Spawn(argv, options);
    if (!child) {
      ADD_FAILURE() << where << "cannot start `" << shown << "`: " << child.error().ToString();
      continue;
    }
    std::optional<int> code = child->Wait(rule->timeout);
    if (!code) {
      child->Signal(SIGINT);  // as a user's Ctrl-C: the run cleans up what it started
      code = child->Wait(60s);
      if (!code) code = child->Stop(5s);
      ADD_FAILURE() << where << "`" << shown << "` still ran after " << rule->timeout.count() << " s";
    }
    const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << where << "exit " << *code << " after " << took_s << " s" << std::endl;
    const std::string stdout_text = testing::ReadWholeFile(out);
    const std::string stderr_text = testing::ReadWholeFile(err);
    auto tail = [](const std::string& s) { return s.size() > 3000 ? "..." + s.substr(s.size() - 3000) : s; };
    EXPECT_EQ(*code, 0) << where << "`" << shown << "`\nstdout:\n" << tail(stdout_text) << "\nstderr:\n" << tail(stderr_text);
    if (!rule->stdout_has.empty()) {
      EXPECT_THAT(stdout_text, ::testing::HasSubstr(rule->stdout_has)) << where << shown;
    }
  }
  for (const auto& [line, seen] : used) {
    EXPECT_TRUE(seen) << "Rules() names a line that is not in " << kReadme << " (any more): " << line;
  }
}

}  // namespace
}  // namespace swarmbox::docs
