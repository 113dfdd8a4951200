// swarmbox-bench raft: the seeded cluster simulator with radio-like settings.
//
//   swarmbox-bench raft [--quick] [--seeds N] [--nodes 5] [--delay_ms 100] [--jitter_ms 20]
//                       [--loss 0.05] [--heartbeat_ms 100] [--election_ms 500] [--tick_ms 50]
//
// scenario=radio_failover: per seed, a cluster on the radio (default 5 drones, 100 ms +- 20 ms
//   one-way, 5% loss) runs 16 s of simulated time with a proposal every 100 ms from a random
//   drone; the leader is crashed at t=5 s and t=10.5 s (restarted 3 s later). Figures:
//   failover = leader crash -> another drone is leader; commit = proposal -> first commit;
//   extra_elections = leader terms beyond the initial one and one per crash (spurious elections).
// scenario=hostile_nN: 3, 5 and 7 nodes with loss, duplication, reordering, partitions and
//   crash/restart, for safety only.
// Exit status 1 when any safety property was violated (the first violations go to stderr, with
// the seed that reproduces them).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "bench.hpp"
#include "hostile_sim_config.hpp"
#include "swarmbox/raft/sim/cluster_sim.hpp"

namespace {

using namespace swarmbox::raft::sim;

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(k, v.size() - 1)];
}

struct Totals {
  int seeds = 0;
  int violating_seeds = 0;
  std::vector<std::string> first_violations;
  std::vector<double> failover_ms, commit_ms;
  long failovers_missed = 0, extra_elections = 0, proposals = 0, dropped = 0;

  void Add(const SimReport& r, int expected_terms) {
    ++seeds;
    if (!r.ok()) {
      ++violating_seeds;
      if (first_violations.size() < 5) first_violations.push_back(r.violations.front());
    }
    failover_ms.insert(failover_ms.end(), r.failover_ms.begin(), r.failover_ms.end());
    commit_ms.insert(commit_ms.end(), r.commit_ms.begin(), r.commit_ms.end());
    failovers_missed += r.failovers_missed;
    if (expected_terms > 0) extra_elections += std::max(0, r.leader_terms - expected_terms);
    proposals += r.proposals;
    dropped += r.proposals_dropped;
  }
  void ReportViolations() const {
    for (const auto& v : first_violations) std::fprintf(stderr, "raft bench: violation: %s\n", v.c_str());
  }
};

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

int RunRaftBench(const swarmbox::bench::Args& args) {
  int worst = 0;
  const long seeds = args.GetInt("seeds", args.quick ? 300 : 10000);
  {
    SimConfig base;
    base.nodes = static_cast<int>(args.GetInt("nodes", 5));
    base.net.delay_ms = args.GetDouble("delay_ms", 100);
    base.net.jitter_ms = args.GetDouble("jitter_ms", 20);
    base.net.loss = args.GetDouble("loss", 0.05);
    base.tick_ms = static_cast<int>(args.GetInt("tick_ms", 50));
    base.heartbeat_ms = static_cast<int>(args.GetInt("heartbeat_ms", 100));
    base.election_timeout_ms = static_cast<int>(args.GetInt("election_ms", 500));
    base.duration_s = 16;
    base.propose_interval_s = 0.1;
    base.leader_crash_at_s = {5, 10.5};
    base.leader_down_s = 3;
    const auto start = std::chrono::steady_clock::now();
    Totals t;
    for (long s = 0; s < seeds; ++s) {
      SimConfig c = base;
      c.seed = static_cast<std::uint64_t>(1 + s);
      const SimReport r = RunSimulation(c);
      t.Add(r, 1 + r.leader_crashes);
    }
    const double wall = Seconds(start);
    std::printf(
        "suite=raft scenario=radio_failover nodes=%d delay_ms=%.0f jitter_ms=%.0f loss=%.2f "
        "heartbeat_ms=%d election_ms=%d violations=%d seeds=%d failovers=%zu failovers_missed=%ld "
        "failover_p50_ms=%.0f failover_p99_ms=%.0f failover_max_ms=%.0f commit_p50_ms=%.0f "
        "commit_p99_ms=%.0f proposals_dropped_pct=%.1f extra_elections=%ld wall_s=%.1f\n",
        base.nodes, base.net.delay_ms, base.net.jitter_ms, base.net.loss, base.heartbeat_ms,
        base.election_timeout_ms, t.violating_seeds, t.seeds, t.failover_ms.size(),
        t.failovers_missed, Percentile(t.failover_ms, 0.5), Percentile(t.failover_ms, 0.99),
        Percentile(t.failover_ms, 1.0), Percentile(t.commit_ms, 0.5), Percentile(t.commit_ms, 0.99),
        100.0 * static_cast<double>(t.dropped) / static_cast<double>(std::max(1L, t.proposals)),
        t.extra_elections, wall);
    t.ReportViolations();
    if (t.violating_seeds > 0) worst = 1;
  }
  // Safety under hostile networks and faults, per cluster size.
  const long hostile_seeds = args.GetInt("hostile_seeds", args.quick ? 100 : 1000);
  for (int nodes : {3, 5, 7}) {
    const auto start = std::chrono::steady_clock::now();
    Totals t;
    for (long s = 0; s < hostile_seeds; ++s) {
      t.Add(RunSimulation(HostileSimConfig(nodes, static_cast<std::uint64_t>(100000 * nodes + s))), 0);
    }
    const std::string scenario = "hostile_n" + std::to_string(nodes);
    std::printf("suite=raft scenario=%s nodes=%d violations=%d seeds=%d commit_p50_ms=%.0f wall_s=%.1f\n",
                scenario.c_str(), nodes, t.violating_seeds, t.seeds, Percentile(t.commit_ms, 0.5),
                Seconds(start));
    t.ReportViolations();
    if (t.violating_seeds > 0) worst = 1;
  }
  return worst;
}

}  // namespace

SWARMBOX_BENCH_SUITE(raft, "Raft cluster simulator: safety over seeds, failover and commit latency",
                     RunRaftBench);
