#include "swarmbox/faults/leader_tracker.hpp"

#include <charconv>

#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::faults {

bool LeaderTracker::Feed(std::string_view line) {
  if (line.find("leader_elected") == std::string_view::npos) return false;
  const LogfmtFields fields = ParseLogfmt(line);
  const auto event = FindField(fields, "event");
  if (!event || *event != "leader_elected") return false;
  auto leader = FindField(fields, "leader");
  if (!leader || leader->empty()) leader = FindField(fields, "node");
  if (!leader || leader->empty()) return false;
  std::int64_t term = term_;
  if (const auto t = FindField(fields, "term")) {
    std::int64_t parsed = 0;
    const auto [end, ec] = std::from_chars(t->data(), t->data() + t->size(), parsed);
    if (ec != std::errc() || end != t->data() + t->size()) return false;
    if (parsed < term_) return false;  // stale
    term = parsed;
  }
  const bool changed = !leader_ || *leader_ != *leader;
  leader_ = *leader;
  term_ = term;
  return changed;
}

Result<std::string> LeaderTracker::Resolve() const {
  if (!leader_) {
    return Error(ErrorCode::kNotFound,
                 "target raft_leader: no event=leader_elected seen in the logs yet (start the fault "
                 "later, or on: \"event=leader_elected\")");
  }
  return *leader_;
}

}  // namespace swarmbox::faults
