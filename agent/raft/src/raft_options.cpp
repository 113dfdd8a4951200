#include "swarmbox/raft/raft_options.hpp"

namespace swarmbox::raft {

Status ReadRaftOptions(const yaml::Node& node, DriverConfig* config) {
  if (!node.is_mapping()) {
    return Error(ErrorCode::kInvalidArgument, "raft options must be a mapping", node.Where());
  }
  DriverConfig c = *config;
  std::uint64_t max_entries = c.max_entries_per_msg;
  yaml::MapReader r(node, "raft");
  r.Optional("tick_ms", &c.tick_ms)
      .Optional("heartbeat_ms", &c.heartbeat_ms)
      .Optional("election_timeout_ms", &c.election_timeout_ms)
      .Optional("snapshot_every_entries", &c.snapshot_every_entries)
      .Optional("max_entries_per_msg", &max_entries)
      .Optional("pre_vote", &c.pre_vote)
      .Optional("check_quorum", &c.check_quorum)
      .Optional("learner_heartbeat_ms", &c.learner_heartbeat_ms)
      .Optional("voter_lost_ms", &c.voter_lost_ms);
  if (auto s = r.Finish(); !s) return s;
  c.max_entries_per_msg = static_cast<std::size_t>(max_entries);
  if (auto s = c.ValidateTiming(); !s) {
    return Error(ErrorCode::kInvalidArgument, s.error().message(), node.Where());
  }
  *config = c;
  return Ok{};
}

}  // namespace swarmbox::raft
