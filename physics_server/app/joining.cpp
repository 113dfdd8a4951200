#include "joining.hpp"

#include <algorithm>

namespace swarmbox::physics {

std::string MissingList(const std::vector<std::string>& missing, std::size_t max_names) {
  if (missing.empty()) return "-";
  std::string out;
  const std::size_t shown = std::min(missing.size(), max_names);
  for (std::size_t i = 0; i < shown; ++i) {
    if (i > 0) out += ',';
    out += missing[i];
  }
  if (missing.size() > shown) out += ",+" + std::to_string(missing.size() - shown);
  return out;
}

LogEvent JoiningEvent(double t_s, const std::string& node, const JoiningStatus& status) {
  LogEvent e(t_s, node, "joining");
  e.Add("joined", static_cast<std::uint64_t>(status.joined))
      .Add("expected", static_cast<std::uint64_t>(status.expected))
      .Add("missing", MissingList(status.missing));
  return e;
}

LogEvent JoinedEvent(double t_s, const std::string& node, const JoiningStatus& status, std::size_t lost,
                     double wait_s) {
  LogEvent e(t_s, node, "joined");
  e.Add("joined", static_cast<std::uint64_t>(status.joined))
      .Add("expected", static_cast<std::uint64_t>(status.expected))
      .Add("lost", static_cast<std::uint64_t>(lost))
      .Add("wait_s", wait_s, 3);
  if (!status.missing.empty()) e.Add("missing", MissingList(status.missing));
  return e;
}

void JoiningClock::Begin(std::int64_t now_ns) {
  begin_ns_ = now_ns;
  next_ns_ = now_ns + every_ns_;
  active_ = true;
  reported_ = false;
}

bool JoiningClock::Due(std::int64_t now_ns) {
  if (!active_ || now_ns < next_ns_) return false;
  // One line however long the caller was away (a stalled server), then the regular period.
  while (next_ns_ <= now_ns) next_ns_ += every_ns_;
  reported_ = true;
  return true;
}

double JoiningClock::End(std::int64_t now_ns) {
  active_ = false;
  return static_cast<double>(now_ns - begin_ns_) * 1e-9;
}

}  // namespace swarmbox::physics
