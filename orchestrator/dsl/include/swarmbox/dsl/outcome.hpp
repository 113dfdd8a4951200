// Outcome and Verdict: the ordered severity every lifecycle step and every trial reports
// (STYLE.md 11, Drake's EventStatus::KeepMoreSevere).
//
// Outcomes are ordered from best to worst: success < timeout < failure < error. A walk of the
// component tree merges the results of its steps with KeepWorse(), so the root sees the worst one;
// on a tie the first reason is kept (it is the cause, later ones are usually consequences).
//
//   Verdict v = Verdict::Success();
//   v.KeepWorse(network.Build());            // error "creating sim: subnet taken"
//   v.KeepWorse(Verdict::Failure("x", "y"));  // ignored: failure is less severe than error
//   // v.outcome == Outcome::kError, v.reason == "creating sim: subnet taken"
//
// The names are the `outcome` values of result.json (ARCHITECTURE.md, contract).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"

namespace swarmbox::dsl {

enum class Outcome : std::uint8_t {
  kSuccess = 0,  // the trial reached its goal / the step did what it should
  kTimeout = 1,  // the trial ran out of (simulated) time without deciding
  kFailure = 2,  // the system under test failed: a collision, a crash, a component died
  kError = 3,    // the infrastructure failed: Docker, images, files, a stalled clock
};

// "success", "timeout", "failure", "error".
std::string_view OutcomeName(Outcome outcome);
// The inverse of OutcomeName; nullopt for anything else.
std::optional<Outcome> ParseOutcome(std::string_view name);

constexpr Outcome Worse(Outcome a, Outcome b) { return a < b ? b : a; }

struct Verdict {
  Outcome outcome = Outcome::kSuccess;
  std::string reason;  // why, for humans; empty on success
  std::string source;  // who decided: a component path ("sar-search/physics"), "timeout", ...

  static Verdict Success() { return {}; }
  static Verdict Of(Outcome outcome, std::string reason, std::string source = {});
  static Verdict Timeout(std::string reason, std::string source = {});
  static Verdict Failure(std::string reason, std::string source = {});
  static Verdict Fail(std::string reason, std::string source = {}) {
    return Failure(std::move(reason), std::move(source));
  }
  static Verdict Err(std::string reason, std::string source = {});
  // An infrastructure error from a Result: outcome error, reason = error.ToString().
  static Verdict FromError(const Error& error, std::string source = {});

  bool ok() const { return outcome == Outcome::kSuccess; }
  // Replaces *this with `other` when `other` is strictly more severe. Returns *this.
  Verdict& KeepWorse(const Verdict& other);
  // "failure: collision (sar-search/scout_1)"
  std::string ToString() const;
};

}  // namespace swarmbox::dsl
