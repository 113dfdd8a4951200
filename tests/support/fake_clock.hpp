// FakeClock: the runner's Clock for tests (the one fake of runner::Clock). Every reading advances
// it by `step_s` first, so time passes as the code under test looks at it; Jump() moves it on at
// once (a slow exec in a sidecar). Thread-safe (the runner reads it from several threads).
// Header-only: the test links swarmbox::runner.
//
//   testing::FakeClock clock;             // 1000.001, 1000.002, ... [s]
//   testing::FakeClock fast(1000, 0.5);   // 1000.5, 1001.0, ...
#pragma once

#include <mutex>

#include "swarmbox/runner/clock.hpp"

namespace swarmbox::testing {

class FakeClock final : public runner::Clock {
 public:
  explicit FakeClock(double start_s = 1000, double step_s = 0.001) : now_(start_s), step_(step_s) {}
  double NowS() override {
    std::lock_guard lock(mu_);
    now_ += step_;
    return now_;
  }
  void Jump(double s) {
    std::lock_guard lock(mu_);
    now_ += s;
  }

 private:
  std::mutex mu_;
  double now_;
  const double step_;
};

}  // namespace swarmbox::testing
