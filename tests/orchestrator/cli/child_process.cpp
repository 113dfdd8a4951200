#include "child_process.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

extern char** environ;

namespace swarmbox::cli::testing {

namespace {

int ExitCodeOf(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

}  // namespace

Result<ChildProcess> ChildProcess::Spawn(const std::vector<std::string>& argv,
                                         const std::string& stdout_path,
                                         const std::string& stderr_path) {
  if (argv.empty()) return Error(ErrorCode::kInvalidArgument, "ChildProcess: empty argv");
  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  const char* out = stdout_path.empty() ? "/dev/null" : stdout_path.c_str();
  const char* err = stderr_path.empty() ? "/dev/null" : stderr_path.c_str();
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  // The child starts with default signal handling, whatever this process (gtest) installed.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  sigaddset(&defaults, SIGPIPE);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, args[0], &actions, &attr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) {
    return Error(ErrorCode::kIo, std::string("cannot start the program: ") + std::strerror(rc), argv[0]);
  }
  return ChildProcess(pid);
}

ChildProcess::ChildProcess(ChildProcess&& other) noexcept
    : pid_(other.pid_), code_(other.code_) {
  other.pid_ = -1;
  other.code_ = 0;
}

ChildProcess& ChildProcess::operator=(ChildProcess&& other) noexcept {
  if (this != &other) {
    KillAndReap();
    pid_ = other.pid_;
    code_ = other.code_;
    other.pid_ = -1;
    other.code_ = 0;
  }
  return *this;
}

ChildProcess::~ChildProcess() { KillAndReap(); }

void ChildProcess::KillAndReap() {
  if (pid_ > 0 && !code_) {
    ::kill(pid_, SIGKILL);
    Reap(/*block=*/true);
  }
}

bool ChildProcess::Reap(bool block) {
  if (code_) return true;
  int status = 0;
  pid_t r;
  do {
    r = ::waitpid(pid_, &status, block ? 0 : WNOHANG);
  } while (r < 0 && errno == EINTR);
  if (r == pid_) {
    code_ = ExitCodeOf(status);
    return true;
  }
  if (r < 0) {  // not our child any more (cannot happen with one owner): treat as gone
    code_ = -1;
    return true;
  }
  return false;
}

bool ChildProcess::Signal(int signal) {
  if (pid_ <= 0 || Reap(/*block=*/false)) return false;
  return ::kill(pid_, signal) == 0;
}

std::optional<int> ChildProcess::Wait(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!Reap(/*block=*/false)) {
    if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return code_;
}

std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

Result<Finished> RunToEnd(const std::vector<std::string>& argv, std::chrono::milliseconds timeout,
                          const std::string& scratch_dir) {
  static std::atomic<int> counter{0};
  const std::string stem = scratch_dir + "/child-" + std::to_string(::getpid()) + "-" +
                           std::to_string(counter.fetch_add(1));
  auto child = ChildProcess::Spawn(argv, stem + ".out", stem + ".err");
  if (!child) return child.error();
  const std::optional<int> code = child->Wait(timeout);
  if (!code) {
    child->Signal(SIGKILL);
    (void)child->Wait(std::chrono::seconds(10));
    return Error(ErrorCode::kTimeout,
                 "did not end within " + std::to_string(timeout.count()) + " ms; stderr: " +
                     ReadWholeFile(stem + ".err"),
                 argv[0]);
  }
  Finished f{*code, ReadWholeFile(stem + ".out"), ReadWholeFile(stem + ".err")};
  ::unlink((stem + ".out").c_str());
  ::unlink((stem + ".err").c_str());
  return f;
}

}  // namespace swarmbox::cli::testing
