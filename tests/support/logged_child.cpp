#include "support/logged_child.hpp"

#include <csignal>
#include <thread>

#include "support/files.hpp"

namespace swarmbox::testing {

LoggedChild::LoggedChild(const std::vector<std::string>& argv, std::string log_path)
    : log_path_(std::move(log_path)) {
  auto child = ChildProcess::Spawn(argv, SpawnOptions{.stdout_path = log_path_, .stderr_path = log_path_});
  if (child) {
    process_.emplace(std::move(*child));
  } else {
    spawn_error_ = child.error().ToString();
  }
}

bool LoggedChild::Signal(int sig) { return process_ && process_->Signal(sig); }

bool LoggedChild::Terminate() { return Signal(SIGTERM); }

int LoggedChild::Wait(std::chrono::milliseconds timeout) {
  if (!process_) return -1;
  return process_->Wait(timeout).value_or(-1);
}

bool LoggedChild::WaitForLog(std::string_view text, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    // Checked before the log is read: output printed just before the exit is still seen.
    const bool ended = !running();
    if (ReadLog().find(text) != std::string::npos) return true;
    if (ended || std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

std::string LoggedChild::ReadLog() const { return ReadWholeFile(log_path_); }

}  // namespace swarmbox::testing
