// LogHub: where the log followers (one thread per container) hand their lines to the runner's
// thread, and where readiness waits are answered.
//
// Thread-safety: every member may be called from any thread.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <regex>
#include <string>
#include <vector>

namespace swarmbox::runner {

struct HubItem {
  enum class Kind { kLine, kStreamEnd };
  Kind kind = Kind::kLine;
  std::string component;
  std::string text;    // the line, or for kStreamEnd the error that ended the stream ("" = EOF)
  double wall_s = 0;   // when it arrived (Clock)
  std::uint64_t generation = 0;  // which follower of the component (a restart starts a new one)
};

class LogHub {
 public:
  enum class Readiness { kReady, kStreamEnded, kTimedOut, kInterrupted };

  void Push(HubItem item);
  // Waits up to `wait` for at least one item, then returns everything queued (oldest first).
  std::vector<HubItem> Drain(std::chrono::milliseconds wait);

  // Readiness: Expect() before the container starts, then WaitReady() blocks until a line of
  // `component` matches, its stream ends, `timeout` passes or `*interrupted` becomes true.
  void Expect(const std::string& component, std::regex pattern);
  Readiness WaitReady(const std::string& component, std::chrono::milliseconds timeout,
                      const std::atomic<bool>* interrupted);

 private:
  struct Pending {
    std::optional<std::regex> pattern;
    bool ready = false;
    bool ended = false;
  };
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<HubItem> queue_;
  std::map<std::string, Pending> pending_;
};

}  // namespace swarmbox::runner
