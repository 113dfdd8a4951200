#include "swarmbox/runner/end_matcher.hpp"

#include <charconv>

#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::runner {

Result<std::regex> CompileLogPattern(const std::string& pattern) {
  try {
    // The lookahead makes the match end at a token boundary (not inside a longer word).
    return std::regex("(?:" + pattern + ")(?![A-Za-z0-9_])", std::regex::ECMAScript);
  } catch (const std::regex_error& e) {
    return Error(ErrorCode::kInvalidArgument,
                 "invalid log pattern '" + pattern + "': " + std::string(e.what()));
  }
}

bool SearchLogPattern(const std::regex& regex, std::string_view line) {
  return std::regex_search(line.begin(), line.end(), regex);
}

Result<EndMatcher> EndMatcher::Compile(const std::vector<dsl::EndCondition>& conditions) {
  EndMatcher m;
  for (const dsl::EndCondition& c : conditions) {
    auto re = CompileLogPattern(c.pattern);
    if (!re) return re.error();
    m.conditions_.push_back({c, std::move(*re)});
  }
  return m;
}

std::optional<dsl::Verdict> EndMatcher::Match(std::string_view component,
                                              std::string_view line) const {
  for (const Compiled& c : conditions_) {
    if (!c.condition.component.empty() && c.condition.component != component) continue;
    if (!SearchLogPattern(c.regex, line)) continue;
    std::string reason =
        c.condition.reason.empty() ? "matched '" + c.condition.pattern + "'" : c.condition.reason;
    return dsl::Verdict::Of(c.condition.outcome, std::move(reason), std::string(component));
  }
  return std::nullopt;
}

std::optional<double> SimTimeOf(std::string_view line) {
  if (line.find("t=") == std::string_view::npos) return std::nullopt;
  auto t = FindField(ParseLogfmt(line), "t");
  if (!t || t->empty()) return std::nullopt;
  double v = 0;
  auto r = std::from_chars(t->data(), t->data() + t->size(), v);
  if (r.ec != std::errc() || r.ptr != t->data() + t->size()) return std::nullopt;
  return v;
}

}  // namespace swarmbox::runner
