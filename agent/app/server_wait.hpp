// ServerWait: how long an agent waits for its first sensor sample (`--sample-timeout`, alias
// `--first-sample-timeout`). A 100-drone start takes longer than any fixed wait (containers
// starting, DDS discovery of 100 participants on a busy host), so the wait is for a sign of the
// physics server, not for the sample itself: every sim/status message (the server's start
// progressing, physics_server/app/joining.hpp) starts the wait afresh. The agent gives up (exit 3)
// only after `timeout` of wall time with no sign of the server at all, or when the server says
// its start is over and this drone was not in it.
//
// Pure: the caller measures the slices (WaitBudget's rule: a slice counts at most its own length,
// so a SIGSTOPped or starved agent does not find its time gone) and hands over what sim/status
// carried.
//
//   ServerWait wait(10s, "scout_16");
//   while (!got && !wait.spent()) {
//     const auto slice = wait.Slice(50ms);
//     ... got = sensor->TakeFor(msg, slice); wait.Spend(elapsed, slice);
//     while (status->Take(ev)) wait.OnStatus(ev);
//   }
//   if (!got) return Error(kUnavailable, wait.Reason(...));
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "swarmbox/bus/messages.hpp"
#include "wait_budget.hpp"

namespace swarmbox::agent {

class ServerWait {
 public:
  ServerWait(std::chrono::milliseconds timeout, std::string drone)
      : timeout_(timeout), budget_(timeout), drone_(std::move(drone)) {}

  // A sim/status message: the server is alive; the wait starts afresh.
  void OnStatus(const bus::Event& status);
  // The wait is over without a sample: no sign of the server for `timeout`, or its start ended
  // without this drone (joined() says which).
  bool spent() const { return budget_.spent() || left_out_; }
  std::chrono::milliseconds Slice(std::chrono::milliseconds max) const { return budget_.Slice(max); }
  void Spend(std::chrono::steady_clock::duration elapsed, std::chrono::milliseconds slice) {
    budget_.Spend(elapsed, slice);
  }

  int statuses() const { return statuses_; }
  // The server ended its start ("joined") without this drone among those it waited for.
  bool left_out() const { return left_out_; }
  // Why the agent gives up, after "no sensor sample on sim/<drone>/sensor": "within 10.0 s and no
  // sign of the physics server (sim/status)" or "for 10.0 s after the physics server's last
  // status (joined 37/101, this drone missing)".
  std::string Reason() const;

 private:
  std::chrono::milliseconds timeout_;
  WaitBudget budget_;
  std::string drone_;
  int statuses_ = 0;
  std::uint64_t joined_ = 0, expected_ = 0;
  bool listed_ = false;  // the last status named this drone as missing
  bool left_out_ = false;
};

}  // namespace swarmbox::agent
