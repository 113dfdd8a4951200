#include "swarmbox/runner/clock.hpp"

#include <chrono>

namespace swarmbox::runner {

double SteadyClock::NowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace swarmbox::runner
