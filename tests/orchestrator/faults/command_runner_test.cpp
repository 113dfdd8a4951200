#include "swarmbox/faults/posix_command_runner.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace swarmbox::faults {
namespace {

using testing::FakeCommandRunner;

TEST(CommandRunner, PosixRunnerCapturesOutputAndExitCode) {
  PosixCommandRunner runner;
  auto out = runner.Run({"sh", "-c", "echo out; echo err >&2; exit 3"});
  ASSERT_TRUE(out) << out.error().ToString();
  EXPECT_EQ(out->exit_code, 3);
  EXPECT_EQ(out->stdout_text, "out\n");
  EXPECT_EQ(out->stderr_text, "err\n");
}

TEST(CommandRunner, PosixRunnerPassesArgvUnchangedWithoutAShell) {
  PosixCommandRunner runner;
  auto out = runner.Run({"printf", "%s|", "a b", "$HOME", "*"});
  ASSERT_TRUE(out) << out.error().ToString();
  EXPECT_EQ(out->stdout_text, "a b|$HOME|*|");
}

TEST(CommandRunner, MissingProgramIsNotFound) {
  PosixCommandRunner runner;
  auto out = runner.Run({"swarmbox-no-such-program-xyz"});
  ASSERT_FALSE(out);
  EXPECT_EQ(out.error().code(), ErrorCode::kNotFound);
  EXPECT_NE(out.error().message().find("cannot run 'swarmbox-no-such-program-xyz'"), std::string::npos);
}

TEST(CommandRunner, RunCommandsStopsAtTheFirstFailureWithTcsMessage) {
  FakeCommandRunner fake;
  fake.answers["tc qdisc"] = CommandOutput{2, "", "Error: Specified qdisc kind is unknown.\n"};
  Status s = RunCommands(fake, {Command{{"iptables", "-w", "-N", "X"}, false},
                                Command{{"tc", "qdisc", "replace", "dev", "eth1", "root", "netem"}, false},
                                Command{{"iptables", "-w", "-X", "X"}, false}});
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().message(),
            "`tc qdisc replace dev eth1 root netem` exited 2: Error: Specified qdisc kind is unknown.");
  EXPECT_EQ(fake.calls.size(), 2u);
}

TEST(CommandRunner, MayFailCommandsAndRunAllContinue) {
  FakeCommandRunner fake;
  fake.answers["tc qdisc"] = CommandOutput{2, "", "Error: Cannot delete qdisc with handle of zero.\n"};
  EXPECT_TRUE(RunCommands(fake, {Command{{"tc", "qdisc", "del", "dev", "lo", "root"}, true}}));
  fake.calls.clear();
  Status s = RunAllCommands(fake, {Command{{"tc", "qdisc", "del"}, false}, Command{{"iptables", "-w", "-X", "X"}, false}});
  ASSERT_FALSE(s);
  EXPECT_EQ(fake.calls.size(), 2u);  // went on after the failure
}

TEST(CommandRunner, PrefixRunnerPrependsItsArgv) {
  FakeCommandRunner fake;
  PrefixCommandRunner in_ns(fake, {"ip", "netns", "exec", "ns1"});
  ASSERT_TRUE(in_ns.Run({"tc", "qdisc", "show"}));
  EXPECT_EQ(fake.calls, std::vector<std::string>{"ip netns exec ns1 tc qdisc show"});
}

}  // namespace
}  // namespace swarmbox::faults
