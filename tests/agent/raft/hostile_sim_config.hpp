// The hostile cluster-simulator set-up that the safety tests (cluster_sim_test.cpp) and
// `swarmbox-bench raft` (raft_bench.cpp, scenario=hostile_nN) both run: 12 s of simulated time on
// a network with 30 ms +- 25 ms delay, 10% loss, 5% duplication, 10% reordering (up to 200 ms),
// a crash every ~2 s (down 0.2-3 s), a partition every ~3 s (0.3-3 s), a snapshot every 8
// entries and a proposal every 50 ms.
#pragma once

#include <cstdint>

#include "swarmbox/raft/sim/cluster_sim.hpp"

namespace swarmbox::raft::sim {

inline SimConfig HostileSimConfig(int nodes, std::uint64_t seed) {
  SimConfig c;
  c.nodes = nodes;
  c.seed = seed;
  c.duration_s = 12;
  c.net.delay_ms = 30;
  c.net.jitter_ms = 25;
  c.net.loss = 0.1;
  c.net.duplicate = 0.05;
  c.net.reorder = 0.1;
  c.net.reorder_ms = 200;
  c.faults.crash_mean_interval_s = 2;
  c.faults.down_min_s = 0.2;
  c.faults.down_max_s = 3;
  c.faults.partition_mean_interval_s = 3;
  c.faults.partition_min_s = 0.3;
  c.faults.partition_max_s = 3;
  c.snapshot_every_entries = 8;
  c.propose_interval_s = 0.05;
  return c;
}

// The hostile set-up with a voting set: `voters` of `nodes` vote (n1..nV), the rest are learners
// paced at 200 ms; the drivers' replacement policy replaces a voter silent for 600 ms, and the
// simulator proposes a random membership change at the leader every ~0.5 s on top (membership
// safety tests and `swarmbox-bench raft` scenario=membership_hostile).
inline SimConfig MembershipSimConfig(int nodes, int voters, std::uint64_t seed) {
  SimConfig c = HostileSimConfig(nodes, seed);
  c.voters = voters;
  c.learner_heartbeat_ms = 200;
  c.voter_lost_ms = 600;
  c.conf_change_interval_s = 0.5;
  return c;
}

}  // namespace swarmbox::raft::sim
