// swarmbox-bench faults: Raft failover after a leader kill, measured in real trials next to the
// Raft cluster simulator's prediction for the same cluster, radio and timings.
//
//   swarmbox-bench faults [--quick] [--trials N] [--seeds N] [--out DIR]
//
// scenario=leader_kill_trials: trials/faults/leader_kill_failover.yaml (five scouts, 100 ms +- 20 ms one
//   way, 5 % loss, the leader SIGKILLed three times and restarted 10 s later) run N times through
//   the trial runner on the local Docker engine, with seeds 1..N (--set seed=i). Failover = the
//   runner's wall time from the kill's `applied` record to the first event=leader_elected naming
//   another drone in a higher term (both in events.jsonl, so the log pipeline's latency, a few ms,
//   is included).
// scenario=leader_kill_sim: swarmbox_raft_sim with the trial's timings (from the file: tick,
//   heartbeat, election timeout), five nodes, the same radio and the same kill schedule, over many
//   seeds. The simulator's jitter is uniform in [-j, +j]; j = 20 x sqrt(3) ms gives the trial's
//   standard deviation (20 ms normal). Failover = leader crash -> another node is leader.
// --quick: one trial and 200 simulator seeds (registered as a ctest, label e2e: it needs Docker).
// Exit status 1 when a trial fails to run or a kill brings no new leader.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench.hpp"
#include "swarmbox/raft/sim/cluster_sim.hpp"
#include "trial_run.hpp"

namespace {

using namespace swarmbox;
using namespace swarmbox::fault_trials;

int RunFaultsBench(const bench::Args& args) {
  const long trials = args.GetInt("trials", args.quick ? 1 : 5);
  const long seeds = args.GetInt("seeds", args.quick ? 200 : 2000);
  const std::string out =
      args.Get("out", (std::filesystem::temp_directory_path() / "swarmbox-bench-faults").string());
  auto base = LoadFaultTrial("leader_kill_failover.yaml");
  if (!base) {
    std::fprintf(stderr, "faults bench: %s\n", base.error().ToString().c_str());
    return 1;
  }
  // The kill schedule of the file: at (sim s) and the time down (the fault's duration).
  std::vector<double> kill_at_s;
  double down_s = 0.0;
  for (const faults::Fault& f : base->faults) {
    if (f.kind() != "kill" || f.start.clock != faults::FaultStart::Clock::kSim) continue;
    kill_at_s.push_back(static_cast<double>(f.start.at_ms) / 1000.0);
    down_s = static_cast<double>(f.duration_ms.value_or(0)) / 1000.0;
  }
  if (kill_at_s.empty() || base->mesh.rules.size() != 1 || !base->mesh.rules[0].to.empty()) {
    std::fprintf(stderr, "faults bench: leader_kill_failover.yaml needs kill faults at simulated times and "
                         "one all-traffic network.mesh rule\n");
    return 1;
  }
  const faults::NetemSpec& radio = base->mesh.rules[0].spec;

  // The simulator's prediction.
  raft::sim::SimConfig sim;
  sim.nodes = static_cast<int>(base->drones.size());
  sim.net.delay_ms = radio.delay_ms;
  sim.net.jitter_ms = radio.jitter_ms * std::sqrt(3.0);
  sim.net.loss = radio.loss;
  sim.tick_ms = base->raft.tick_ms;
  sim.heartbeat_ms = base->raft.heartbeat_ms;
  sim.election_timeout_ms = base->raft.election_timeout_ms;
  sim.duration_s = base->timeout.sim.seconds();
  sim.propose_interval_s = 1e6;  // the trial proposes nothing (mission kind plan)
  sim.leader_crash_at_s = kill_at_s;
  sim.leader_down_s = down_s;
  std::vector<double> sim_failover;
  int sim_missed = 0, violations = 0;
  for (long s = 0; s < seeds; ++s) {
    raft::sim::SimConfig c = sim;
    c.seed = static_cast<std::uint64_t>(1 + s);
    const raft::sim::SimReport r = raft::sim::RunSimulation(c);
    sim_failover.insert(sim_failover.end(), r.failover_ms.begin(), r.failover_ms.end());
    sim_missed += r.failovers_missed;
    if (!r.ok()) ++violations;
  }
  std::printf(
      "suite=faults scenario=leader_kill_sim nodes=%d delay_ms=%.0f jitter_uniform_ms=%.1f "
      "loss=%.2f tick_ms=%d heartbeat_ms=%d election_ms=%d seeds=%ld failovers=%zu "
      "failovers_missed=%d violations=%d failover_p50_ms=%.0f failover_p99_ms=%.0f "
      "failover_max_ms=%.0f\n",
      sim.nodes, sim.net.delay_ms, sim.net.jitter_ms, sim.net.loss, sim.tick_ms, sim.heartbeat_ms,
      sim.election_timeout_ms, seeds, sim_failover.size(), sim_missed, violations,
      Percentile(sim_failover, 0.5), Percentile(sim_failover, 0.99), Percentile(sim_failover, 1.0));
  std::fflush(stdout);

  // The real trials.
  auto api = ConnectDocker();
  if (!api) {
    std::fprintf(stderr, "faults bench: %s\n", api.error().ToString().c_str());
    return 1;
  }
  std::vector<double> failover;
  int missed = 0, kills = 0, failed_runs = 0;
  for (long i = 0; i < trials; ++i) {
    auto spec = LoadFaultTrial("leader_kill_failover.yaml", {"seed=" + std::to_string(1 + i)});
    if (!spec) {
      std::fprintf(stderr, "faults bench: %s\n", spec.error().ToString().c_str());
      return 1;
    }
    TrialRunConfig cfg;
    cfg.out_dir = out;
    auto run = RunFaultTrial(**api, *spec, cfg);
    if (!run) {
      std::fprintf(stderr, "faults bench: trial %ld: %s\n", i + 1, run.error().ToString().c_str());
      ++failed_runs;
      continue;
    }
    const dsl::Verdict& v = run->outcome.result.verdict;
    if (v.outcome != dsl::Outcome::kTimeout) {
      std::fprintf(stderr, "faults bench: trial %ld ended %s: %s (%s)\n", i + 1,
                   std::string(dsl::OutcomeName(v.outcome)).c_str(), v.reason.c_str(),
                   run->outcome.trial_dir.c_str());
      ++failed_runs;
      continue;
    }
    for (const Failover& f : Failovers(run->events)) {
      ++kills;
      if (f.new_leader.empty()) {
        ++missed;
      } else {
        failover.push_back(f.failover_ms);
      }
    }
    std::filesystem::remove_all(run->outcome.trial_dir);
  }
  std::printf(
      "suite=faults scenario=leader_kill_trials nodes=%zu delay_ms=%.0f jitter_ms=%.0f "
      "distribution=normal loss=%.2f tick_ms=%d heartbeat_ms=%d election_ms=%d trials=%ld "
      "failed_runs=%d leader_kills=%d failovers=%zu failovers_missed=%d failover_p50_ms=%.0f "
      "failover_p99_ms=%.0f failover_max_ms=%.0f sim_failover_p50_ms=%.0f "
      "sim_failover_p99_ms=%.0f\n",
      base->drones.size(), radio.delay_ms, radio.jitter_ms, radio.loss,
      base->raft.tick_ms, base->raft.heartbeat_ms, base->raft.election_timeout_ms, trials,
      failed_runs, kills, failover.size(), missed, Percentile(failover, 0.5),
      Percentile(failover, 0.99), Percentile(failover, 1.0), Percentile(sim_failover, 0.5),
      Percentile(sim_failover, 0.99));
  return (failed_runs > 0 || missed > 0 || failover.empty() || violations > 0) ? 1 : 0;
}

}  // namespace

SWARMBOX_BENCH_SUITE(faults, "Raft failover after leader kills: real trials vs the cluster simulator",
                     RunFaultsBench);
