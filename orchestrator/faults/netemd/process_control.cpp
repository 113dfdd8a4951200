#include "process_control.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace swarmbox::faults {
namespace {

constexpr const char* kProgramName = "swarmbox-netemd";  // as /proc/<pid>/comm shows it (15 chars)

void WriteAll(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

// 'R', 'S', 'Z', ... or 0 when the process is gone.
char ProcessState(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return 0;
  const auto close = line.rfind(')');
  if (close == std::string::npos || close + 2 >= line.size()) return 0;
  return line[close + 2];
}

}  // namespace

namespace {

// The parent's side: reads the pipe until the child closes it; "ok" means ready, anything else is
// the child's own stderr lines (already prefixed), printed before reaping the child.
int WaitForDaemonReady(pid_t pid, int read_fd) {
  std::string message;
  char buf[512];
  for (;;) {
    const ssize_t n = ::read(read_fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    message.append(buf, static_cast<std::size_t>(n));
  }
  ::close(read_fd);
  if (message == "ok") return 0;
  std::fputs(message.empty() ? "swarmbox-netemd: the daemon exited before it was ready\n" : message.c_str(),
             stderr);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return 1;
}

// The child's readiness: pidfile written, stdio on /dev/null, "ok" down the pipe, pipe closed.
// A pidfile that cannot be written ends the child with the reason down the pipe.
void AnnounceReady(const std::string& pidfile, int ready_fd) {
  if (!pidfile.empty()) {
    std::ofstream out(pidfile, std::ios::trunc);
    out << ::getpid() << "\n";
    if (!out) {
      WriteAll(ready_fd, "swarmbox-netemd: cannot write pidfile " + pidfile + "\n");
      ::_exit(1);
    }
  }
  const int null_fd = ::open("/dev/null", O_RDWR);
  if (null_fd >= 0) {
    ::dup2(null_fd, 0);
    ::dup2(null_fd, 1);
    ::dup2(null_fd, 2);
    ::close(null_fd);
  }
  WriteAll(ready_fd, "ok");
  ::close(ready_fd);
}

// The child's side: a new session, stderr into the pipe until ready (so the parent prints the
// errors of a failed start), then the work; exits with its code and never returns.
[[noreturn]] void RunDaemonChild(int ready_fd, const std::string& pidfile,
                                 const std::function<int(const std::function<void()>& ready)>& ready_work) {
  ::setsid();
  bool said_ready = false;
  const int saved_stderr = ::dup(2);
  ::dup2(ready_fd, 2);
  const int code = ready_work([&] {
    if (saved_stderr >= 0) {
      ::dup2(saved_stderr, 2);
      ::close(saved_stderr);
    }
    AnnounceReady(pidfile, ready_fd);
    said_ready = true;
  });
  if (!said_ready) ::close(ready_fd);
  if (!pidfile.empty() && said_ready) ::unlink(pidfile.c_str());
  ::_exit(code);
}

}  // namespace

int Daemonize(const std::string& pidfile,
              const std::function<int(const std::function<void()>& ready)>& ready_work) {
  int fds[2];
  if (::pipe(fds) != 0) {
    std::fprintf(stderr, "swarmbox-netemd: pipe: %s\n", std::strerror(errno));
    return 1;
  }
  const pid_t pid = ::fork();
  if (pid < 0) {
    std::fprintf(stderr, "swarmbox-netemd: fork: %s\n", std::strerror(errno));
    return 1;
  }
  if (pid > 0) {  // parent: wait for "ok" or the child's error text
    ::close(fds[1]);
    return WaitForDaemonReady(pid, fds[0]);
  }
  ::close(fds[0]);
  RunDaemonChild(fds[1], pidfile, ready_work);
}

Status StopByPidfile(const std::string& pidfile, int timeout_ms) {
  std::ifstream in(pidfile);
  long pid_value = 0;
  if (!(in >> pid_value) || pid_value <= 1) {
    return Error(ErrorCode::kNotFound, "no daemon pid in " + pidfile, "swarmbox-netemd stop");
  }
  const pid_t pid = static_cast<pid_t>(pid_value);
  std::ifstream comm_file("/proc/" + std::to_string(pid) + "/comm");
  std::string comm;
  std::getline(comm_file, comm);
  if (comm.empty() || ProcessState(pid) == 0 || ProcessState(pid) == 'Z') {
    ::unlink(pidfile.c_str());
    return Ok{};  // already gone
  }
  if (comm != kProgramName) {
    return Error(ErrorCode::kInvalidArgument,
                 "pid " + std::to_string(pid) + " in " + pidfile + " is '" + comm + "', not swarmbox-netemd",
                 "swarmbox-netemd stop");
  }
  if (::kill(pid, SIGTERM) != 0 && errno != ESRCH) {
    return Error(ErrorCode::kIo, std::string("kill: ") + std::strerror(errno), "swarmbox-netemd stop");
  }
  for (int waited_ms = 0; waited_ms < timeout_ms; waited_ms += 10) {
    const char state = ProcessState(pid);
    if (state == 0 || state == 'Z') {
      ::unlink(pidfile.c_str());
      return Ok{};
    }
    timespec ts{0, 10 * 1000 * 1000};
    ::nanosleep(&ts, nullptr);
  }
  return Error(ErrorCode::kTimeout, "pid " + std::to_string(pid) + " still running after SIGTERM",
               "swarmbox-netemd stop");
}

int SleepAsInit() {
  sigset_t mask;
  sigemptyset(&mask);
  sigaddset(&mask, SIGTERM);
  sigaddset(&mask, SIGINT);
  sigaddset(&mask, SIGCHLD);
  sigprocmask(SIG_BLOCK, &mask, nullptr);
  for (;;) {
    int sig = 0;
    if (sigwait(&mask, &sig) != 0) continue;
    if (sig == SIGCHLD) {
      while (::waitpid(-1, nullptr, WNOHANG) > 0) {
      }
      continue;
    }
    return 0;
  }
}

}  // namespace swarmbox::faults
