// WaitBudget: a wall-clock wait of `total`, spent in slices, for the agent's liveness bounds (the
// first sample, a stall, a camera frame, an external brain's answer). Each slice counts at most
// its own length, so a process stopped or starved in the middle of one (SIGSTOP, docker pause)
// resumes with the rest of its budget instead of a deadline long gone.
//
//   WaitBudget budget(std::chrono::milliseconds(3000));
//   while (!got && !budget.spent()) {
//     const auto slice = budget.Slice(std::chrono::milliseconds(50));
//     const auto start = std::chrono::steady_clock::now();
//     got = sub->TakeFor(msg, slice);
//     budget.Spend(std::chrono::steady_clock::now() - start, slice);
//   }
#pragma once

#include <algorithm>
#include <chrono>

namespace swarmbox::agent {

class WaitBudget {
 public:
  explicit WaitBudget(std::chrono::milliseconds total) : left_(total) {}
  bool spent() const { return left_ <= std::chrono::milliseconds(0); }
  std::chrono::milliseconds Slice(std::chrono::milliseconds max) const { return std::min(left_, max); }
  void Spend(std::chrono::steady_clock::duration elapsed, std::chrono::milliseconds slice) {
    left_ -= std::min(std::chrono::duration_cast<std::chrono::milliseconds>(elapsed), slice);
    if (elapsed < std::chrono::milliseconds(1)) left_ -= std::chrono::milliseconds(1);  // always progress
  }

 private:
  std::chrono::milliseconds left_;
};

}  // namespace swarmbox::agent
