#include "interrupt.hpp"

#include <csignal>

#include "commands.hpp"

namespace swarmbox::cli {

namespace {

std::atomic<bool> g_interrupted{false};
std::atomic<int> g_signal{0};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");
static_assert(std::atomic<int>::is_always_lock_free, "set from a signal handler");

extern "C" void OnInterrupt(int signal) {
  int none = 0;
  g_signal.compare_exchange_strong(none, signal);  // the first one decides the exit code
  g_interrupted.store(true);
  std::signal(signal, SIG_DFL);  // async-signal-safe; the next one is fatal
}

}  // namespace

const std::atomic<bool>& InstallInterruptHandlers() {
  struct sigaction sa {};
  sa.sa_handler = OnInterrupt;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  return g_interrupted;
}

int InterruptSignal() { return g_signal.load(); }

int InterruptExitCode() {
  const int signal = g_signal.load();
  return signal == 0 ? kExitOutcome : 128 + signal;
}

const char* InterruptName() {
  return g_signal.load() == SIGTERM ? "interrupted (SIGTERM)" : "interrupted (Ctrl-C)";
}

}  // namespace swarmbox::cli
