#include "swarmbox/faults/netemd_args.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace swarmbox::faults {
namespace {

TEST(NetemdArgs, RunArgvRoundTrips) {
  NetemdArgs a;
  a.queue = 7;
  a.delay = {100000, 20000, DelayDistribution::kParetoNormal, 0.25, 0.1, 0.5, 3};
  a.seed = 123456789012345ULL;
  a.queue_maxlen = 4096;
  a.pidfile = "/run/swarmbox-netemd-7.pid";
  a.daemonize = true;
  const auto argv = NetemdRunArgv("/usr/bin/swarmbox-netemd", a);
  EXPECT_EQ(argv, (std::vector<std::string>{
                      "/usr/bin/swarmbox-netemd", "run", "--queue", "7", "--delay-us", "100000", "--jitter-us",
                      "20000", "--distribution", "paretonormal", "--correlation", "0.25", "--reorder", "0.1",
                      "--reorder-correlation", "0.5", "--reorder-gap", "3", "--seed", "123456789012345",
                      "--queue-maxlen", "4096", "--pidfile", "/run/swarmbox-netemd-7.pid", "--daemonize"}));
  auto parsed = ParseNetemdRunArgs(std::vector<std::string>(argv.begin() + 2, argv.end()));
  ASSERT_TRUE(parsed) << parsed.error().ToString();
  EXPECT_EQ(*parsed, a);
}

TEST(NetemdArgs, GilbertElliottFlagsRoundTrip) {
  NetemdArgs a;
  a.queue = 1;
  a.gilbert_elliott = GilbertElliott{0.02, 0.25, 0.9, 0.01};
  const auto argv = NetemdRunArgv("netemd", a);
  const std::vector<std::string> tail(argv.end() - 8, argv.end());
  EXPECT_EQ(tail, (std::vector<std::string>{"--ge-p", "0.02", "--ge-r", "0.25", "--ge-loss-bad", "0.9",
                                            "--ge-loss-good", "0.01"}));
  auto parsed = ParseNetemdRunArgs(std::vector<std::string>(argv.begin() + 2, argv.end()));
  ASSERT_TRUE(parsed) << parsed.error().ToString();
  EXPECT_EQ(*parsed, a);
  // Without the model no --ge-* flag is written, and none parsed means no loss.
  a.gilbert_elliott.reset();
  const auto plain = NetemdRunArgv("netemd", a);
  EXPECT_EQ(std::find(plain.begin(), plain.end(), "--ge-p"), plain.end());
  EXPECT_FALSE(ParseNetemdRunArgs({"--queue", "1"})->gilbert_elliott.has_value());
}

TEST(NetemdArgs, CorruptFlagRoundTripsAndIsOnlyWrittenWhenSet) {
  NetemdArgs a;
  a.queue = 2;
  a.corrupt = 0.1;
  const auto argv = NetemdRunArgv("netemd", a);
  EXPECT_EQ(std::vector<std::string>(argv.end() - 2, argv.end()), (std::vector<std::string>{"--corrupt", "0.1"}));
  auto parsed = ParseNetemdRunArgs(std::vector<std::string>(argv.begin() + 2, argv.end()));
  ASSERT_TRUE(parsed) << parsed.error().ToString();
  EXPECT_EQ(*parsed, a);
  a.corrupt = 0.0;
  const auto plain = NetemdRunArgv("netemd", a);
  EXPECT_EQ(std::find(plain.begin(), plain.end(), "--corrupt"), plain.end());
  EXPECT_EQ(ParseNetemdRunArgs({"--queue", "1"})->corrupt, 0.0);
}

TEST(NetemdArgs, StopArgv) {
  EXPECT_EQ(NetemdStopArgv("/usr/bin/swarmbox-netemd", "/run/x.pid"),
            (std::vector<std::string>{"/usr/bin/swarmbox-netemd", "stop", "--pidfile", "/run/x.pid"}));
}

TEST(NetemdArgs, RejectsBadFlagsWithTheReason) {
  struct Case {
    std::vector<std::string> words;
    const char* message;
  };
  const Case cases[] = {
      {{"--delay-us", "10"}, "--queue: required"},
      {{"--queue", "70000"}, "--queue: expected an integer in [0, 65535], got '70000'"},
      {{"--queue", "1", "--distribution", "gamma"}, "--distribution: expected uniform, normal, pareto or paretonormal"},
      {{"--queue", "1", "--reorder", "1.5"}, "--reorder: expected a fraction in [0, 1], got '1.5'"},
      {{"--queue", "1", "--pidfile", "rel.pid"}, "--pidfile: expected an absolute path"},
      {{"--queue", "1", "--speed", "3"}, "--speed: unknown flag"},
      {{"--queue"}, "--queue: missing value"},
      {{"--queue", "1", "--ge-p", "0.1", "--ge-r", "0.2"},
       "--ge-p: a Gilbert-Elliott model needs all of --ge-p, --ge-r, --ge-loss-bad and --ge-loss-good"},
      {{"--queue", "1", "--ge-loss-bad", "2"}, "--ge-loss-bad: expected a fraction in [0, 1], got '2'"},
      {{"--queue", "1", "--corrupt", "-0.1"}, "--corrupt: expected a fraction in [0, 1], got '-0.1'"},
  };
  for (const Case& c : cases) {
    auto parsed = ParseNetemdRunArgs(c.words);
    ASSERT_FALSE(parsed) << c.message;
    EXPECT_EQ(parsed.error().code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(parsed.error().message().rfind(c.message, 0), 0u) << parsed.error().message();
  }
}

}  // namespace
}  // namespace swarmbox::faults
