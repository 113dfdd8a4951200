#include "swarmbox/dsl/outcome.hpp"

#include <utility>

namespace swarmbox::dsl {

std::string_view OutcomeName(Outcome outcome) {
  switch (outcome) {
    case Outcome::kSuccess: return "success";
    case Outcome::kTimeout: return "timeout";
    case Outcome::kFailure: return "failure";
    case Outcome::kError: return "error";
  }
  return "error";
}

std::optional<Outcome> ParseOutcome(std::string_view name) {
  for (Outcome o : {Outcome::kSuccess, Outcome::kTimeout, Outcome::kFailure, Outcome::kError}) {
    if (OutcomeName(o) == name) return o;
  }
  return std::nullopt;
}

Verdict Verdict::Of(Outcome outcome, std::string reason, std::string source) {
  Verdict v;
  v.outcome = outcome;
  v.reason = std::move(reason);
  v.source = std::move(source);
  return v;
}

Verdict Verdict::Timeout(std::string reason, std::string source) {
  return Of(Outcome::kTimeout, std::move(reason), std::move(source));
}
Verdict Verdict::Failure(std::string reason, std::string source) {
  return Of(Outcome::kFailure, std::move(reason), std::move(source));
}
Verdict Verdict::Err(std::string reason, std::string source) {
  return Of(Outcome::kError, std::move(reason), std::move(source));
}
Verdict Verdict::FromError(const Error& error, std::string source) {
  return Of(Outcome::kError, error.ToString(), std::move(source));
}

Verdict& Verdict::KeepWorse(const Verdict& other) {
  if (other.outcome > outcome) *this = other;
  return *this;
}

std::string Verdict::ToString() const {
  std::string s(OutcomeName(outcome));
  if (!reason.empty()) s += ": " + reason;
  if (!source.empty()) s += " (" + source + ")";
  return s;
}

}  // namespace swarmbox::dsl
