// swarmbox-bench raft: the seeded cluster simulator with radio-like settings.
//
//   swarmbox-bench raft [--quick] [--seeds N] [--nodes 5] [--delay_ms 100] [--jitter_ms 20]
//                       [--loss 0.05] [--heartbeat_ms 100] [--election_ms 500] [--tick_ms 50]
//                       [--scenario swarm] [--swarm_seeds N] [--membership_seeds N]
//
// scenario=radio_failover: per seed, a cluster on the radio (default 5 drones, 100 ms +- 20 ms
//   one-way, 5% loss) runs 16 s of simulated time with a proposal every 100 ms from a random
//   drone; the leader is crashed at t=5 s and t=10.5 s (restarted 3 s later). Figures:
//   failover = leader crash -> another drone is leader; commit = proposal -> first commit;
//   extra_elections = leader terms beyond the initial one and one per crash (spurious elections).
// scenario=hostile_nN: 3, 5 and 7 nodes with loss, duplication, reordering, partitions and
//   crash/restart, for safety only.
// scenario=swarm_n100 (--swarm_seeds, --swarm_nodes 100, --voters 5): the swarm at scale, 5 voters
//   and 95 learners on the radio above, 20 s per seed, a proposal every 200 ms: the leader is
//   crashed at t=5 s (down 3 s), a voter that is not the leader at t=11 s (down for good).
//   Figures: violations; failover; replacement = voter crash -> the leader's configuration has 5
//   voters again without it (removal after voter_lost_ms = 3 x election timeout, then a promotion);
//   conf_changes per seed; leader_fps = frames the leader sent per simulated second;
//   leader_burst_max = most frames the leader queued in one step (its radio queue holds 50).
// scenario=membership_hostile (--membership_seeds): 9 nodes, 3 voters, the hostile network and
//   faults above plus a random membership change at the leader every ~0.5 s on top of the
//   replacement policy (voter_lost 0.6 s), for safety only.
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

// The swarm at scale (see the banner): returns 1 when any seed violated a safety property.
int RunSwarmScenarios(const swarmbox::bench::Args& args) {
  int worst = 0;
  {
    SimConfig base;
    base.nodes = static_cast<int>(args.GetInt("swarm_nodes", 100));
    base.voters = static_cast<int>(args.GetInt("voters", 5));
    base.net.delay_ms = args.GetDouble("delay_ms", 100);
    base.net.jitter_ms = args.GetDouble("jitter_ms", 20);
    base.net.loss = args.GetDouble("loss", 0.05);
    base.tick_ms = static_cast<int>(args.GetInt("tick_ms", 50));
    base.heartbeat_ms = static_cast<int>(args.GetInt("heartbeat_ms", 100));
    base.election_timeout_ms = static_cast<int>(args.GetInt("election_ms", 500));
    base.learner_heartbeat_ms = static_cast<int>(args.GetInt("learner_heartbeat_ms", 1000));
    base.duration_s = 20;
    base.propose_interval_s = 0.2;
    base.leader_crash_at_s = {5};
    base.leader_down_s = 3;
    base.voter_crash_at_s = {11};
    base.voter_down_s = 30;
    const long seeds = args.GetInt("swarm_seeds", args.quick ? 10 : 1000);
    const auto start = std::chrono::steady_clock::now();
    Totals t;
    std::vector<double> replacement_ms, leader_fps;
    long replacements_missed = 0, conf_changes = 0;
    int burst_max = 0;
    for (long s = 0; s < seeds; ++s) {
      SimConfig c = base;
      c.seed = static_cast<std::uint64_t>(500000 + s);
      const SimReport r = RunSimulation(c);
      t.Add(r, 0);
      replacement_ms.insert(replacement_ms.end(), r.replacement_ms.begin(), r.replacement_ms.end());
      replacements_missed += r.replacements_missed + (r.replacement_ms.empty() ? 1 : 0);
      conf_changes += r.conf_changes;
      leader_fps.push_back(static_cast<double>(r.leader_messages) / c.duration_s);
      burst_max = std::max(burst_max, r.leader_burst_max);
    }
    std::printf(
        "suite=raft scenario=swarm_n%d nodes=%d voters=%d learner_heartbeat_ms=%d violations=%d seeds=%d "
        "failovers=%zu failovers_missed=%ld failover_p50_ms=%.0f failover_p99_ms=%.0f "
        "replacements=%zu replacements_missed=%ld replacement_p50_ms=%.0f replacement_p99_ms=%.0f "
        "replacement_max_ms=%.0f conf_changes_per_seed=%.1f leader_fps_p50=%.0f leader_fps_max=%.0f "
        "leader_burst_max=%d commit_p50_ms=%.0f commit_p99_ms=%.0f wall_s=%.1f\n",
        base.nodes, base.nodes, base.voters, base.learner_heartbeat_ms, t.violating_seeds, t.seeds,
        t.failover_ms.size(), t.failovers_missed, Percentile(t.failover_ms, 0.5), Percentile(t.failover_ms, 0.99),
        replacement_ms.size(), replacements_missed, Percentile(replacement_ms, 0.5),
        Percentile(replacement_ms, 0.99), Percentile(replacement_ms, 1.0),
        static_cast<double>(conf_changes) / static_cast<double>(std::max(1L, seeds)), Percentile(leader_fps, 0.5),
        Percentile(leader_fps, 1.0), burst_max, Percentile(t.commit_ms, 0.5), Percentile(t.commit_ms, 0.99),
        Seconds(start));
    t.ReportViolations();
    if (t.violating_seeds > 0) worst = 1;
  }
  {
    const long seeds = args.GetInt("membership_seeds", args.quick ? 100 : 3000);
    const auto start = std::chrono::steady_clock::now();
    Totals t;
    long conf_changes = 0;
    for (long s = 0; s < seeds; ++s) {
      const SimReport r = RunSimulation(MembershipSimConfig(9, 3, static_cast<std::uint64_t>(700000 + s)));
      conf_changes += r.conf_changes;
      t.Add(r, 0);
    }
    std::printf("suite=raft scenario=membership_hostile nodes=9 voters=3 violations=%d seeds=%d "
                "conf_changes_per_seed=%.1f commit_p50_ms=%.0f wall_s=%.1f\n",
                t.violating_seeds, t.seeds, static_cast<double>(conf_changes) / static_cast<double>(std::max(1L, seeds)),
                Percentile(t.commit_ms, 0.5), Seconds(start));
    t.ReportViolations();
    if (t.violating_seeds > 0) worst = 1;
  }
  return worst;
}

int RunRaftBench(const swarmbox::bench::Args& args) {
  // --scenario swarm: only the swarm-scale scenarios (swarm_n100, membership_hostile).
  if (args.Get("scenario", "all") == "swarm") return RunSwarmScenarios(args);
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
  worst = std::max(worst, RunSwarmScenarios(args));
  return worst;
}

}  // namespace

SWARMBOX_BENCH_SUITE(raft, "Raft cluster simulator: safety over seeds, failover and commit latency",
                     RunRaftBench);
