// LeaderTracker: who the current Raft leader is, from the log events the agents print
// (`t=12.340 node=drone_2 event=leader_elected term=3 leader=drone_2`). Pure: the runner feeds it
// every log line it sees; the `raft_leader` target resolves to the leader of the latest election.
//
//   LeaderTracker leaders;
//   for (auto& line : lines) leaders.Feed(line);
//   auto who = leaders.Resolve();     // "drone_2", or kNotFound before any election
//
// An election with a lower term than one already seen is stale (a late log line) and ignored; a
// line without `term` counts as the latest. Not thread-safe.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"

namespace swarmbox::faults {

class LeaderTracker {
 public:
  // Returns true when the line changed the leader.
  bool Feed(std::string_view line);
  const std::optional<std::string>& leader() const { return leader_; }
  std::int64_t term() const { return term_; }
  Result<std::string> Resolve() const;

 private:
  std::optional<std::string> leader_;
  std::int64_t term_ = -1;
};

}  // namespace swarmbox::faults
