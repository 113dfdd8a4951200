// The command line of swarmbox-raft-node (raft_node_main.cpp), parsed without I/O.
//
//   swarmbox-raft-node --name scout_1 --members scout_1,scout_2,lifter --data-dir /tmp/r1
//       [--domain 180] [--interface lo] [--middleware cyclonedds|fastdds] [--seed 42]
//       [--propose-every-ms 500] [--duration-s 0] [--tick-ms 50] [--heartbeat-ms 100]
//       [--election-timeout-ms 500]
//
// --propose-every-ms 0 (default) never proposes; N > 0: when leader, propose the next demo
// mission command (demo_mission.hpp) every N ms. --duration-s 0 (default) runs until
// SIGTERM/SIGINT. Errors are kInvalidArgument naming the flag; ParseRaftNodeArgs never exits.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/node_driver.hpp"

namespace swarmbox::raft_service {

struct RaftNodeOptions {
  raft::DriverConfig driver;  // self = --name, members = --members, seed = --seed, timings
  std::string data_dir;
  int domain = 0;
  std::string interface = "lo";
  std::string middleware = "cyclonedds";
  int propose_every_ms = 0;
  double duration_s = 0;
  bool help = false;
};

// `args` without argv[0].
Result<RaftNodeOptions> ParseRaftNodeArgs(const std::vector<std::string>& args);
std::string RaftNodeUsage();

}  // namespace swarmbox::raft_service
