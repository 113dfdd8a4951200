#include "swarmbox/faults/posix_command_runner.hpp"

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

extern char** environ;

namespace swarmbox::faults {

namespace {

void CloseFd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

}  // namespace

namespace {

// Spawns argv with stdin on /dev/null and stdout/stderr into the pipes' write ends, which are
// closed here either way; a failed spawn also closes the read ends.
Result<pid_t> SpawnIntoPipes(const std::vector<std::string>& argv, int out_pipe[2], int err_pipe[2]) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, out_pipe[1], 1);
  posix_spawn_file_actions_adddup2(&actions, err_pipe[1], 2);
  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = ::posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  CloseFd(out_pipe[1]);
  CloseFd(err_pipe[1]);
  if (rc != 0) {
    CloseFd(out_pipe[0]);
    CloseFd(err_pipe[0]);
    return Error(rc == ENOENT ? ErrorCode::kNotFound : ErrorCode::kIo,
                 "cannot run '" + argv[0] + "': " + std::strerror(rc), CommandText(argv));
  }
  return pid;
}

// Reads both pipes until each reaches end of file (or fails), closing each as it ends.
void ReadUntilClosed(int out_fd, int err_fd, CommandOutput& output) {
  pollfd fds[2] = {{out_fd, POLLIN, 0}, {err_fd, POLLIN, 0}};
  std::string* sinks[2] = {&output.stdout_text, &output.stderr_text};
  int open_fds = 2;
  char buf[4096];
  while (open_fds > 0) {
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || fds[i].revents == 0) continue;
      const ssize_t n = ::read(fds[i].fd, buf, sizeof buf);
      if (n > 0) {
        sinks[i]->append(buf, static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        ::close(fds[i].fd);
        fds[i].fd = -1;
        --open_fds;
      }
    }
  }
}

// The exit status, or 128 + the signal for a killed child (as a shell reports it).
int WaitForExitCode(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

Result<CommandOutput> PosixCommandRunner::Run(const std::vector<std::string>& argv) {
  SWARMBOX_CHECK(!argv.empty());
  int out_pipe[2] = {-1, -1};
  int err_pipe[2] = {-1, -1};
  if (::pipe2(out_pipe, O_CLOEXEC) != 0 || ::pipe2(err_pipe, O_CLOEXEC) != 0) {
    const int e = errno;
    CloseFd(out_pipe[0]);
    CloseFd(out_pipe[1]);
    return Error(ErrorCode::kIo, std::string("pipe: ") + std::strerror(e), CommandText(argv));
  }
  auto pid = SpawnIntoPipes(argv, out_pipe, err_pipe);
  if (!pid) return pid.error();
  CommandOutput output;
  ReadUntilClosed(out_pipe[0], err_pipe[0], output);
  output.exit_code = WaitForExitCode(*pid);
  return output;
}

}  // namespace swarmbox::faults
