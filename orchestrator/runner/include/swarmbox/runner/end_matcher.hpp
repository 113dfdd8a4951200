// EndMatcher: a trial's end conditions, compiled, fed one log line at a time (pure).
//
//   auto m = EndMatcher::Compile(trial.end_conditions());
//   if (auto v = m->Match("scout_1", "t=12.3 node=scout_1 event=collision other=scout_2"))
//     trial.RaiseShutdown(*v);   // failure: collision (scout_1)
//
// A pattern is an ECMAScript regex searched in the line that must end at a token boundary, so
// `event=crash` does not fire on `event=crash_landing`. Conditions are tried in declaration order;
// the first match wins.
#pragma once

#include <optional>
#include <regex>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/dsl/trial.hpp"

namespace swarmbox::runner {

class EndMatcher {
 public:
  // kInvalidArgument naming the pattern when one is not a valid regex.
  static Result<EndMatcher> Compile(const std::vector<dsl::EndCondition>& conditions);

  // The verdict of the first condition matching `line` of `component`'s log. Reason: the
  // condition's reason, or "matched '<pattern>'"; source: the component.
  std::optional<dsl::Verdict> Match(std::string_view component, std::string_view line) const;

 private:
  struct Compiled {
    dsl::EndCondition condition;
    std::regex regex;
  };
  std::vector<Compiled> conditions_;
};

// A search pattern that also requires the match to end at a token boundary.
Result<std::regex> CompileLogPattern(const std::string& pattern);
bool SearchLogPattern(const std::regex& regex, std::string_view line);

// The simulated time [s] of a logfmt line (its `t=` field), if it has one.
std::optional<double> SimTimeOf(std::string_view line);

}  // namespace swarmbox::runner
