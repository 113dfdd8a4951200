#include "swarmbox/images/process_capture.hpp"

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

extern char** environ;

namespace swarmbox::images {
namespace {

constexpr std::size_t kReadChunkBytes = 16384;
constexpr int kSignalExitBase = 128;  // the shells' convention for "ended by a signal"

struct Pipe {
  int fd[2] = {-1, -1};
  ~Pipe() {
    for (int f : fd) {
      if (f >= 0) close(f);
    }
  }
  void CloseEnd(int i) {
    if (fd[i] >= 0) close(fd[i]);
    fd[i] = -1;
  }
};

// Starts argv with stdin /dev/null and stdout/stderr into the pipes' write ends (a bare name is
// looked up in PATH; a path is used as it is).
Result<pid_t> Spawn(const std::vector<std::string>& argv, const Pipe& out, const Pipe& err, const std::string& what) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, out.fd[1], 1);
  posix_spawn_file_actions_adddup2(&actions, err.fd[1], 2);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const bool search = argv.front().find('/') == std::string::npos;
  const int rc = search ? posix_spawnp(&pid, argv.front().c_str(), &actions, nullptr, args.data(), environ)
                        : posix_spawn(&pid, argv.front().c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    return Error(ErrorCode::kNotFound, std::string("cannot start: ") + std::strerror(rc), what);
  }
  return pid;
}

// Reads both pipes until each is closed (or fails), into run->out and run->err.
void ReadUntilClosed(int out_fd, int err_fd, CapturedRun* run) {
  pollfd fds[2] = {{out_fd, POLLIN, 0}, {err_fd, POLLIN, 0}};
  int open_fds = 2;
  char buffer[kReadChunkBytes];
  while (open_fds > 0) {
    if (poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || (fds[i].revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
      const ssize_t n = read(fds[i].fd, buffer, sizeof(buffer));
      if (n > 0) {
        (i == 0 ? run->out : run->err).append(buffer, static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        fds[i].fd = -1;
        --open_fds;
      }
    }
  }
}

// The child's exit code once it has ended (128 + the signal when a signal ended it).
Result<int> WaitExitCode(pid_t pid, const std::string& what) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return Error(ErrorCode::kIo, std::string("waitpid: ") + std::strerror(errno), what);
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : kSignalExitBase + WTERMSIG(status);
}

}  // namespace

Result<CapturedRun> RunCapture(const std::vector<std::string>& argv) {
  const std::string what = argv.empty() ? std::string("(empty argv)") : argv.front();
  if (argv.empty()) return Error(ErrorCode::kInvalidArgument, "no program to run", what);
  Pipe out, err;
  if (pipe2(out.fd, O_CLOEXEC) != 0 || pipe2(err.fd, O_CLOEXEC) != 0) {
    return Error(ErrorCode::kIo, std::string("pipe: ") + std::strerror(errno), what);
  }
  auto pid = Spawn(argv, out, err, what);
  if (!pid) return pid.error();
  out.CloseEnd(1);
  err.CloseEnd(1);
  CapturedRun run;
  ReadUntilClosed(out.fd[0], err.fd[0], &run);
  auto exit_code = WaitExitCode(*pid, what);
  if (!exit_code) return exit_code.error();
  run.exit_code = *exit_code;
  return run;
}

}  // namespace swarmbox::images
