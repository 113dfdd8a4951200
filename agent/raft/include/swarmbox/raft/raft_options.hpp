// Raft options of a trial: the timing and tuning keys a trial description may set for the
// swarm's consensus, read into a DriverConfig (the rest of which, self/members/seed, comes from
// the drone list and the trial seed).
//
//   # trial.yaml (for example under each agent, or one mapping for the whole swarm)
//   raft: {heartbeat_ms: 100, election_timeout_ms: 500, tick_ms: 50}
//
//   DriverConfig cfg;                       // defaults: node_driver.hpp "Timing defaults"
//   if (const yaml::Node* n = trial.Find("raft")) {
//     if (auto s = ReadRaftOptions(*n, &cfg); !s) return s.error();   // "trial.yaml:12:9: ..."
//   }
//
// Keys (all optional): tick_ms, heartbeat_ms, election_timeout_ms, snapshot_every_entries,
// max_entries_per_msg, pre_vote, check_quorum, learner_heartbeat_ms, voter_lost_ms (the voting set
// itself comes from the drone list: DriverConfig::voters). Unknown keys, wrong types and timings that cannot
// work are kInvalidArgument errors located at the mapping (file:line:col).
#pragma once

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/raft/node_driver.hpp"

namespace swarmbox::raft {

Status ReadRaftOptions(const yaml::Node& node, DriverConfig* config);

}  // namespace swarmbox::raft
