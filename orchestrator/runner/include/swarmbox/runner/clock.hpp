// Clock: monotonic wall time for the runner (the real one is std::chrono::steady_clock; tests use
// a fake). Simulated time never comes from here: it is read from the physics server's log.
#pragma once

namespace swarmbox::runner {

class Clock {
 public:
  virtual ~Clock() = default;
  // Seconds since an arbitrary fixed point; never decreases.
  virtual double NowS() = 0;
};

class SteadyClock final : public Clock {
 public:
  double NowS() override;
};

}  // namespace swarmbox::runner
