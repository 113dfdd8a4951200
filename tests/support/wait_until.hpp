// WaitUntil: polls a condition until it holds or a timeout passes (for tests that watch other
// threads or processes; the timeout is a hang guard, never a speed assertion).
#pragma once

#include <chrono>
#include <functional>
#include <thread>

namespace swarmbox::testing {

// Calls `pred` every `poll` until it returns true or `timeout` has passed; its last value.
inline bool WaitUntil(const std::function<bool()>& pred, std::chrono::milliseconds timeout,
                      std::chrono::milliseconds poll = std::chrono::milliseconds(10)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (pred()) return true;
    std::this_thread::sleep_for(poll);
  }
  return pred();
}

}  // namespace swarmbox::testing
