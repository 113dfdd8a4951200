// The real ssh client (integration): a tunnel to a closed loopback port fails fast with the
// classified reason. The two-host experiment test covers a working tunnel.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "swarmbox/hosts/host.hpp"

namespace swarmbox::hosts {
namespace {

// The real ssh client against a loopback port nothing listens on: the tunnel fails fast with the
// classified reason and leaves no process and no socket behind.
TEST(SshTunnel, ARefusedConnectionIsReportedAsUnreachable) {
  const std::string dir = "/tmp/sbx-tunnel-" + std::to_string(::getpid());
  auto spec = ParseHostSpec("ssh://nobody@127.0.0.1:1?known_hosts=/dev/null");
  ASSERT_TRUE(spec);
  auto tunnel = SshTunnel::Open(*spec, dir, std::chrono::seconds(15));
  ASSERT_FALSE(tunnel);
  EXPECT_EQ(tunnel.error().code(), ErrorCode::kUnavailable) << tunnel.error().ToString();
  EXPECT_NE(tunnel.error().message().find("cannot reach nobody@127.0.0.1:1 over ssh"),
            std::string::npos)
      << tunnel.error().ToString();
  EXPECT_FALSE(std::filesystem::exists(dir + "/nobody_127.0.0.1_1.sock"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace swarmbox::hosts
