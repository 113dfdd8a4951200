// A swarm in the suite (issue #18): trials/swarm_100.yaml with 49 scouts and the lifter, rtf 0,
// 25 simulated seconds, through the trial runner on the real engine. Every drone joins (simulated
// time moves: the lockstep has all 50), a Raft leader is elected among the 5 voters (raft.voters;
// the other 45 drones are learners) and every drone hears of it, no
// drone is lost to the infrastructure, and nothing of the run stays on the engine. The figures
// line (swarm_figures.hpp) and the wall time go to the log.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "swarm_run.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/docker/remove_labelled.hpp"

namespace swarmbox::swarm {
namespace {

// 49 scouts and the lifter: the 50-drone swarm. Discovery on sim is a star around the
// physics server (ARCHITECTURE.md, "Two radio models"); with every agent discovering every other,
// no start of more than about 31 agents completed on this host.
constexpr int kScouts = 49;
constexpr double kSimS = 25.0;

// Docker 20.10 (Debian 12's docker.io) can lose one decrement of a network's stored endpoint count
// when many of its containers exit at once: the network then refuses removal with "has active
// endpoints" though nothing is attached, until dockerd restarts (its log then says "Fixing
// inconsistent endpoint_cnt ... Expected=0, Actual=1"; moby#43286, moby#42119). It hit this
// 50-container teardown once in a CI run (2026-11-27). A network the run left passes only when it
// is exactly that: no container attached, the engine still refusing with that message, and the
// runner's result naming it as a problem with the advice (`swarmbox gc` after a restart).
void ExpectOnlyTheEnginesStaleEndpoint(docker::DockerApi& api, const docker::NetworkInfo& network,
                                       const std::vector<std::string>& problems) {
  auto info = api.InspectNetwork(network.id);
  ASSERT_TRUE(info) << info.error().ToString();
  EXPECT_TRUE(info->container_ids.empty())
      << "network " << network.name << " left with " << info->container_ids.size() << " endpoints";
  const Status again = api.RemoveNetwork(network.id);
  if (again) {
    ADD_FAILURE() << "network " << network.name << " was left though the engine removes it";
    return;
  }
  EXPECT_TRUE(docker::IsStaleEndpointRefusal(again)) << again.error().ToString();
  bool reported = false;
  for (const std::string& p : problems) {
    reported = reported || (p.find(network.name) != std::string::npos &&
                            p.find("moby#43286") != std::string::npos);
  }
  EXPECT_TRUE(reported) << "the runner did not report network " << network.name << " as left";
  std::printf("SwarmE2e: network %s kept by the engine's stale endpoint count (moby#43286), "
              "reported by the runner; removed by `swarmbox gc` after a dockerd restart\n",
              network.name.c_str());
}

TEST(SwarmE2e, FiftyDronesJoinElectALeaderLoseNoneAndCleanUp) {
  auto api = ConnectDocker();
  ASSERT_TRUE(api) << api.error().ToString();
  auto spec = LoadSwarmTrial(kScouts, kSimS);
  ASSERT_TRUE(spec) << spec.error().ToString();
  ASSERT_EQ(spec->drones.size(), static_cast<std::size_t>(kScouts + 1));
  SwarmRunConfig cfg;
  cfg.out_dir = (std::filesystem::temp_directory_path() / "swarmbox-swarm-e2e").string();
  const auto started = std::chrono::steady_clock::now();
  auto run = RunSwarmTrial(**api, *spec, cfg);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  ASSERT_TRUE(run) << run.error().ToString();
  const SwarmFigures& f = run->figures;
  std::printf("SwarmE2e: %s test_wall_s=%.1f dir=%s\n", FormatSwarmLine(f, kScouts).c_str(), wall_s,
              run->outcome.trial_dir.c_str());
  const dsl::Verdict& verdict = run->outcome.result.verdict;
  // A short SAR mission ends on its simulated timeout (or, sooner, complete): never a failure.
  EXPECT_TRUE(verdict.outcome == dsl::Outcome::kTimeout || verdict.outcome == dsl::Outcome::kSuccess)
      << verdict.ToString() << " (" << run->outcome.trial_dir << ")";
  EXPECT_EQ(f.joined, kScouts + 1) << "agents that logged event=ready";
  ASSERT_TRUE(f.start_s) << "simulated time never moved: not every drone joined the lockstep";
  EXPECT_GE(f.sim_s, kSimS - 0.5);
  EXPECT_EQ(f.lost, 0);

  // A leader, and every drone hears of it (event=leader_elected names it on each drone).
  std::map<std::string, std::string> leader_of;  // drone -> the last leader it logged
  for (const std::string& line : run->events) {
    if (line.find("\"leader_elected\"") == std::string::npos) continue;
    auto doc = yaml::Parse(line, "events.jsonl");
    ASSERT_TRUE(doc) << line;
    leader_of[doc->Find("component")->scalar()] = doc->Find("leader")->scalar();
  }
  EXPECT_EQ(leader_of.size(), spec->drones.size()) << "drones that logged a leader";
  std::set<std::string> leaders;
  for (const auto& [drone, leader] : leader_of) leaders.insert(leader);
  EXPECT_EQ(leaders.size(), 1u) << "drones disagree on the last leader";
  // Only the voters (raft.voters: the first drones in file order) lead; the rest are learners.
  ASSERT_GT(spec->raft.voters, 0);
  std::set<std::string> voters;
  for (int k = 0; k < spec->raft.voters; ++k) voters.insert(spec->drones[static_cast<std::size_t>(k)].name);
  for (const std::string& leader : leaders) EXPECT_EQ(voters.count(leader), 1u) << leader << " is no voter";

  // Nothing labelled with the run stays (the runner removed it; RunSwarmTrial's sweep found nothing
  // it could not remove), apart from a network the engine itself will not let go of (above).
  docker::LabelSelector mine;
  mine.equals[std::string(docker::kLabelRun)] = run->outcome.result.run_id;
  auto containers = (*api)->ListContainers(mine, /*all=*/true);
  ASSERT_TRUE(containers) << containers.error().ToString();
  EXPECT_TRUE(containers->empty());
  auto networks = (*api)->ListNetworks(mine);
  ASSERT_TRUE(networks) << networks.error().ToString();
  for (const docker::NetworkInfo& n : *networks) {
    ExpectOnlyTheEnginesStaleEndpoint(**api, n, run->outcome.result.problems);
  }
  if (!HasFailure()) std::filesystem::remove_all(run->outcome.trial_dir);
}

}  // namespace
}  // namespace swarmbox::swarm
