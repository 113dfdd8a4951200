// Host specs, the ssh tunnel's argv and the classification of ssh failures (pure).
#include "swarmbox/hosts/host_spec.hpp"

#include <gtest/gtest.h>

#include <algorithm>


namespace swarmbox::hosts {
namespace {

TEST(HostSpec, LocalAndSshForms) {
  auto local = ParseHostSpec("local?slots=3");
  ASSERT_TRUE(local) << local.error().ToString();
  EXPECT_EQ(local->kind, HostSpec::Kind::kLocal);
  EXPECT_EQ(local->slots, 3);
  EXPECT_EQ(local->name(), "local");

  auto ssh = ParseHostSpec(
      "ssh://root@10.250.0.2:2222?slots=2&socket=/run/x/docker.sock&identity=/k/id&known_hosts=/k/kh");
  ASSERT_TRUE(ssh) << ssh.error().ToString();
  EXPECT_EQ(ssh->kind, HostSpec::Kind::kSsh);
  EXPECT_EQ(ssh->user, "root");
  EXPECT_EQ(ssh->host, "10.250.0.2");
  EXPECT_EQ(ssh->port, 2222);
  EXPECT_EQ(ssh->slots, 2);
  EXPECT_EQ(ssh->socket, "/run/x/docker.sock");
  EXPECT_EQ(ssh->identity, "/k/id");
  EXPECT_EQ(ssh->known_hosts, "/k/kh");
  EXPECT_EQ(ssh->name(), "root@10.250.0.2:2222");

  auto plain = ParseHostSpec("ssh://lab3");
  ASSERT_TRUE(plain);
  EXPECT_EQ(plain->port, 22);
  EXPECT_EQ(plain->socket, "/var/run/docker.sock");
  EXPECT_EQ(plain->name(), "lab3");
}

TEST(HostSpec, ErrorsSayWhatIsWrong) {
  auto msg = [](std::string_view text) {
    auto r = ParseHostSpec(text);
    return r ? std::string("ok") : r.error().message();
  };
  EXPECT_EQ(msg("tcp://x").substr(0, 33), "host 'tcp://x': unknown kind of h");
  EXPECT_NE(msg("ssh://a@b:99999").find("bad port '99999'"), std::string::npos);
  EXPECT_NE(msg("local?slots=0").find("slots must be 1..64"), std::string::npos);
  EXPECT_NE(msg("local?colour=red").find("unknown option 'colour'"), std::string::npos);
  EXPECT_NE(msg("ssh://b?socket=rel").find("socket must be an absolute path"), std::string::npos);
  EXPECT_NE(msg("ssh://@b").find("empty user name"), std::string::npos);
  auto twice = ParseHostSpecs({"local,local?slots=2"});
  ASSERT_FALSE(twice);
  EXPECT_NE(twice.error().message().find("given twice"), std::string::npos);
  auto many = ParseHostSpecs({"local?slots=2,ssh://a@b", "ssh://c@d"});
  ASSERT_TRUE(many);
  EXPECT_EQ(many->size(), 3u);
}

TEST(SshTunnelArgv, ChecksHostKeysInBatchModeAndForwardsTheSocket) {
  auto spec = ParseHostSpec("ssh://root@h:2200?socket=/run/d.sock&identity=/k/id&known_hosts=/k/kh");
  ASSERT_TRUE(spec);
  const auto argv = SshTunnelArgv(*spec, "/tmp/w/h.sock", "/tmp/w");
  auto has_pair = [&](std::string_view a, std::string_view b) {
    for (std::size_t i = 0; i + 1 < argv.size(); ++i) {
      if (argv[i] == a && argv[i + 1] == b) return true;
    }
    return false;
  };
  EXPECT_EQ(argv.front(), "ssh");
  EXPECT_EQ(argv[1], "-N");
  EXPECT_TRUE(has_pair("-o", "BatchMode=yes"));
  EXPECT_TRUE(has_pair("-o", "StrictHostKeyChecking=yes"));
  EXPECT_TRUE(has_pair("-o", "UserKnownHostsFile=/k/kh"));
  EXPECT_TRUE(has_pair("-i", "/k/id"));
  EXPECT_TRUE(has_pair("-o", "ExitOnForwardFailure=yes"));
  EXPECT_TRUE(has_pair("-o", "ControlMaster=auto"));
  EXPECT_TRUE(has_pair("-o", "ControlPath=/tmp/w/cm-%C"));
  EXPECT_TRUE(has_pair("-p", "2200"));
  EXPECT_TRUE(has_pair("-L", "/tmp/w/h.sock:/run/d.sock"));
  EXPECT_EQ(argv.back(), "root@h");
  EXPECT_EQ(std::count(argv.begin(), argv.end(), "StrictHostKeyChecking=no"), 0);
}

TEST(ClassifySshFailure, NamesTheCauseAndWhatToDo) {
  auto spec = *ParseHostSpec("ssh://root@10.250.0.2?known_hosts=/t/kh&identity=/t/key");
  Error hostkey = ClassifySshFailure(spec, "Host key verification failed.", 255);
  EXPECT_EQ(hostkey.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(hostkey.message().find("is not in /t/kh"), std::string::npos) << hostkey.message();
  Error auth = ClassifySshFailure(spec, "root@10.250.0.2: Permission denied (publickey).", 255);
  EXPECT_NE(auth.message().find("authentication to root@10.250.0.2 was refused"), std::string::npos);
  EXPECT_NE(auth.message().find("/t/key"), std::string::npos);
  Error sock = ClassifySshFailure(
      spec, "channel 2: open failed: connect failed: Permission denied", -1);
  EXPECT_NE(sock.message().find("cannot be opened by this user (permission denied"),
            std::string::npos)
      << sock.message();
  Error gone = ClassifySshFailure(spec, "channel 2: open failed: connect failed: No such file", -1);
  EXPECT_NE(gone.message().find("does not answer (is dockerd running there?)"), std::string::npos);
  Error refused = ClassifySshFailure(spec, "ssh: connect to host 10.250.0.2 port 22: Connection refused", 255);
  EXPECT_EQ(refused.code(), ErrorCode::kUnavailable);
  EXPECT_TRUE(refused.retryable());
  Error repeated = ClassifySshFailure(
      spec, "channel 2: open failed: connect failed: open failed\nchannel 3: open failed: connect "
            "failed: open failed\nchannel 4: open failed: connect failed: open failed\n", -1);
  EXPECT_EQ(repeated.message().substr(repeated.message().find(" [ssh:")),
            " [ssh: channel: open failed: connect failed: open failed]");
  Error changed = ClassifySshFailure(spec, "@ WARNING: REMOTE HOST IDENTIFICATION HAS CHANGED! @", 255);
  EXPECT_NE(changed.message().find("host key of root@10.250.0.2 changed"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::hosts
