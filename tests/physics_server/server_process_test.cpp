// The swarmbox-physics program as a process (posix_spawn, no shell): bad input gives
// `file:line:col: message` and exit 2; SIGTERM ends a run cleanly with truth.csv flushed.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "test_util.hpp"

extern char** environ;

namespace swarmbox::physics {
namespace {

struct Child {
  pid_t pid = -1;
  int out_fd = -1;  // stdout + stderr
};

Child Spawn(const std::vector<std::string>& args) {
  int fds[2];
  EXPECT_EQ(::pipe(fds), 0);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, fds[1], 1);
  posix_spawn_file_actions_adddup2(&fa, fds[1], 2);
  posix_spawn_file_actions_addclose(&fa, fds[0]);
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  Child c;
  EXPECT_EQ(posix_spawn(&c.pid, argv[0], &fa, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&fa);
  ::close(fds[1]);
  c.out_fd = fds[0];
  return c;
}

// Reads until EOF or until `until` appears; returns what was read.
std::string ReadOutput(int fd, const std::string& until = {}) {
  std::string out;
  char buf[4096];
  while (true) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;
    out.append(buf, static_cast<std::size_t>(n));
    if (!until.empty() && out.find(until) != std::string::npos) break;
  }
  return out;
}

int Wait(pid_t pid) {
  int status = 0;
  EXPECT_EQ(::waitpid(pid, &status, 0), pid);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

TEST(ServerProcess, BadWorldFileIsReportedWithPositionAndExitTwo) {
  const std::string world = WriteTemp("bad_world.yaml", "name: w\nwind: {mean_m_s: [1, 2], gusts: 3}\n");
  Child c = Spawn({SWARMBOX_PHYSICS_EXE, "--world", world, "--drone", "a:x500:0,0,0", "--airframes-dir",
                   testing::TrialsDir() + "/airframes"});
  const std::string out = ReadOutput(c.out_fd);
  ::close(c.out_fd);
  EXPECT_EQ(Wait(c.pid), 2);
  EXPECT_EQ(out, "swarmbox-physics: " + world + ":2:18: world: 'mean_m_s': expected a list of 3 values\n");
}

TEST(ServerProcess, BadAirframeFileIsReportedWithPositionAndExitTwo) {
  // The shipped x500 with one bad value.
  std::ifstream shipped(testing::AirframePath("x500"));
  std::stringstream text;
  text << shipped.rdbuf();
  std::string yaml = text.str();
  const std::size_t at = yaml.find("\nmass_kg: 2.0643");
  ASSERT_NE(at, std::string::npos);
  yaml.replace(at, 16, "\nmass_kg: heavy");
  const int line = static_cast<int>(std::count(yaml.begin(), yaml.begin() + static_cast<long>(at), '\n')) + 2;
  const std::string af = WriteTemp("bad_af.yaml", yaml);
  Child c = Spawn({SWARMBOX_PHYSICS_EXE, "--world", testing::WorldPath("open_field"), "--drone", "a:" + af + ":0,0,0"});
  const std::string out = ReadOutput(c.out_fd);
  ::close(c.out_fd);
  EXPECT_EQ(Wait(c.pid), 2);
  EXPECT_EQ(out.rfind("swarmbox-physics: " + af + ":" + std::to_string(line) + ":10: airframe: 'mass_kg': ", 0), 0u)
      << out;
}

TEST(ServerProcess, UsageErrorExitsTwo) {
  Child c = Spawn({SWARMBOX_PHYSICS_EXE, "--drone", "a:x500:0,0,0"});
  const std::string out = ReadOutput(c.out_fd);
  ::close(c.out_fd);
  EXPECT_EQ(Wait(c.pid), 2);
  EXPECT_NE(out.find("--world is required"), std::string::npos) << out;
}

TEST(ServerProcess, SigtermEndsTheRunWithTruthFlushed) {
  const std::string truth = ::testing::TempDir() + "sigterm_truth.csv";
  const std::string domain = std::to_string(100 + (::getpid() + 37) % 100);
  Child c = Spawn({SWARMBOX_PHYSICS_EXE, "--world", testing::WorldPath("open_field"), "--drone", "a:x500:0,0,0",
                   "--truth", truth, "--truth-rate-hz", "100", "--domain", domain, "--join-timeout", "0.2",
                   "--step-timeout", "0.2", "--rtf", "1", "--no-cameras"});
  const std::string ready = ReadOutput(c.out_fd, "event=ready");
  ASSERT_NE(ready.find("node=physics event=ready world=open_field drones=1"), std::string::npos) << ready;
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  ASSERT_EQ(::kill(c.pid, SIGTERM), 0);
  const std::string rest = ReadOutput(c.out_fd);
  ::close(c.out_fd);
  EXPECT_EQ(Wait(c.pid), 0) << rest;
  EXPECT_NE(rest.find("event=drone_lost a=a"), std::string::npos) << rest;  // no agent answered
  EXPECT_NE(rest.find("event=stopped reason=signal"), std::string::npos) << rest;
  std::ifstream in(truth);
  std::stringstream s;
  s << in.rdbuf();
  const std::string csv = s.str();
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.back(), '\n');  // whole rows only
  EXPECT_GT(std::count(csv.begin(), csv.end(), '\n'), 10);  // ~0.6 s of simulated time at 100 Hz
}

}  // namespace
}  // namespace swarmbox::physics
