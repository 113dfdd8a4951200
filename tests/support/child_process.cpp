#include "support/child_process.hpp"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <thread>

#include "support/files.hpp"

namespace swarmbox::testing {

namespace {

int ExitCodeOf(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

pid_t WaitPid(pid_t pid, int* status, int flags) {
  pid_t r;
  do {
    r = ::waitpid(pid, status, flags);
  } while (r < 0 && errno == EINTR);
  return r;
}

// Makes `fd` (0, 1 or 2) the file at `path`; errno on failure, 0 on success. Only
// async-signal-safe calls: it runs in the forked child.
int Redirect(int fd, const char* path, int flags) {
  const int opened = ::open(path, flags, 0644);
  if (opened < 0) return errno;
  if (opened != fd) {
    if (::dup2(opened, fd) < 0) return errno;
    ::close(opened);
  }
  return 0;
}

// The forked child: its own process group, killed with the spawning thread, default signal
// handling, the redirections, then exec. On failure it writes errno to `report_fd` and exits 127.
[[noreturn]] void ExecChild(char* const* argv, const char* out, const char* err, bool err_to_out,
                            const char* dir, pid_t parent, int report_fd) {
  ::setpgid(0, 0);
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(126);  // the parent died before prctl took effect
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  for (int s = 1; s < NSIG; ++s) {
    if (s != SIGKILL && s != SIGSTOP) ::sigaction(s, &dfl, nullptr);  // glibc's own: EINVAL, fine
  }
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  int e = Redirect(STDIN_FILENO, "/dev/null", O_RDONLY);
  if (e == 0 && out != nullptr) e = Redirect(STDOUT_FILENO, out, O_WRONLY | O_CREAT | O_TRUNC);
  if (e == 0 && err_to_out && ::dup2(STDOUT_FILENO, STDERR_FILENO) < 0) e = errno;
  if (e == 0 && !err_to_out && err != nullptr) e = Redirect(STDERR_FILENO, err, O_WRONLY | O_CREAT | O_TRUNC);
  if (e == 0 && dir != nullptr && ::chdir(dir) != 0) e = errno;
  if (e == 0) {
    ::execv(argv[0], argv);
    e = errno;
  }
  [[maybe_unused]] const ssize_t n = ::write(report_fd, &e, sizeof e);
  ::_exit(127);
}

}  // namespace

Result<ChildProcess> ChildProcess::Spawn(const std::vector<std::string>& argv, const SpawnOptions& options) {
  if (argv.empty()) return Error(ErrorCode::kInvalidArgument, "ChildProcess: empty argv");
  // Everything the child needs is built before fork: after it, the child may only call
  // async-signal-safe functions (this process has other threads).
  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const char* out = options.stdout_path.empty() ? nullptr : options.stdout_path.c_str();
  const char* err = options.stderr_path.empty() ? nullptr : options.stderr_path.c_str();
  const bool err_to_out = out != nullptr && err != nullptr && options.stdout_path == options.stderr_path;
  const char* dir = options.working_dir.empty() ? nullptr : options.working_dir.c_str();

  // The exec failure channel: closed on a successful exec (O_CLOEXEC), errno written otherwise.
  int report[2];
  if (::pipe2(report, O_CLOEXEC) != 0) {
    return Error(ErrorCode::kIo, std::string("pipe: ") + std::strerror(errno), argv[0]);
  }
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(report[0]);
    ::close(report[1]);
    return Error(ErrorCode::kIo, std::string("fork: ") + std::strerror(e), argv[0]);
  }
  if (pid == 0) {
    ::close(report[0]);
    ExecChild(args.data(), out, err, err_to_out, dir, parent, report[1]);
  }
  ::close(report[1]);
  ::setpgid(pid, pid);  // the child does it too: whichever comes first (a kill of the group works at once)
  int child_errno = 0;
  ssize_t n;
  do {
    n = ::read(report[0], &child_errno, sizeof child_errno);
  } while (n < 0 && errno == EINTR);
  ::close(report[0]);
  if (n > 0) {  // exec (or a redirection) failed: the child exits 127
    int status = 0;
    WaitPid(pid, &status, 0);
    return Error(ErrorCode::kIo, std::string("cannot start the program: ") + std::strerror(child_errno),
                 argv[0]);
  }
  return ChildProcess(pid);
}

Result<ChildProcess> ChildProcess::Spawn(const std::vector<std::string>& argv, const std::string& stdout_path,
                                         const std::string& stderr_path) {
  return Spawn(argv, SpawnOptions{.stdout_path = stdout_path.empty() ? "/dev/null" : stdout_path,
                                  .stderr_path = stderr_path.empty() ? "/dev/null" : stderr_path});
}

ChildProcess::ChildProcess(ChildProcess&& other) noexcept : pid_(other.pid_), code_(other.code_) {
  other.pid_ = -1;
  other.code_ = -1;
}

ChildProcess& ChildProcess::operator=(ChildProcess&& other) noexcept {
  if (this != &other) {
    KillAndReap();
    pid_ = other.pid_;
    code_ = other.code_;
    other.pid_ = -1;
    other.code_ = -1;
  }
  return *this;
}

ChildProcess::~ChildProcess() { KillAndReap(); }

void ChildProcess::KillAndReap() {
  if (pid_ > 0 && !code_) {
    // The group first (the child's own children), while the unreaped child keeps its id taken.
    ::kill(-pid_, SIGKILL);
    ::kill(pid_, SIGKILL);
    Reap(/*block=*/true);
  }
}

bool ChildProcess::Reap(bool block) {
  if (code_) return true;
  int status = 0;
  const pid_t r = WaitPid(pid_, &status, block ? 0 : WNOHANG);
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

bool ChildProcess::running() { return pid_ > 0 && !Reap(/*block=*/false); }

bool ChildProcess::Signal(int signal) {
  if (!running()) return false;
  return ::kill(pid_, signal) == 0;
}

std::optional<int> ChildProcess::Wait(std::chrono::milliseconds timeout) {
  if (pid_ <= 0) return code_;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!Reap(/*block=*/false)) {
    if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return code_;
}

int ChildProcess::Stop(std::chrono::milliseconds grace) {
  if (pid_ <= 0) return code_.value_or(-1);
  if (Signal(SIGTERM) && !Wait(grace)) KillAndReap();
  Reap(/*block=*/true);
  return *code_;
}

Result<Finished> RunToEnd(const std::vector<std::string>& argv, std::chrono::milliseconds timeout,
                          const std::string& scratch_dir) {
  static std::atomic<int> counter{0};
  const std::string stem =
      scratch_dir + "/child-" + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
  auto child = ChildProcess::Spawn(argv, stem + ".out", stem + ".err");
  if (!child) return child.error();
  const std::optional<int> code = child->Wait(timeout);
  if (!code) {
    child->Signal(SIGKILL);
    (void)child->Wait(std::chrono::seconds(10));
    return Error(ErrorCode::kTimeout,
                 "did not end within " + std::to_string(timeout.count()) +
                     " ms; stderr: " + ReadWholeFile(stem + ".err"),
                 argv[0]);
  }
  Finished f{*code, ReadWholeFile(stem + ".out"), ReadWholeFile(stem + ".err")};
  ::unlink((stem + ".out").c_str());
  ::unlink((stem + ".err").c_str());
  return f;
}

std::string SelfExecutable() {
  char buf[4096];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof(buf) - 1);
  if (n <= 0) return {};
  return std::string(buf, static_cast<std::size_t>(n));
}

}  // namespace swarmbox::testing
