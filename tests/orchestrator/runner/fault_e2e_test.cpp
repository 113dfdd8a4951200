// Faults on the real engine with the real programs: a short mission kind plan trial (physics server
// + two agents flying take-off, hover, land and running Raft on the mesh) with a network.mesh
// impairment. While it flies, the test looks into each agent's fault sidecar (docker exec) and
// checks that the impairment is in place on the mesh interface with the mechanism this host allows
// (here: no sch_netem, so the userspace path: NFQUEUE + swarmbox-netemd for delay/jitter, iptables
// statistic on ingress for loss), that nothing touches the sim interface, and that the agents are
// unprivileged. Afterwards: the trial succeeded (the lockstep over the untouched sim link worked),
// events.jsonl records the mechanism and each mesh apply/remove (the removal left to the sidecars'
// namespaces: afterwards no SWARMBOX chain or NFQUEUE rule is in the host's iptables and the
// sidecars' swarmbox-netemd processes are gone), and nothing labelled remains.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <thread>

#include "swarmbox/faults/docker_exec_runner.hpp"
#include "swarmbox/faults/mechanism.hpp"
#include "swarmbox/images/process_capture.hpp"
#include "swarmbox/runner/naming.hpp"
#include "swarmbox/runner/runner.hpp"
#include "support/files.hpp"
#include "support/trial_on_docker.hpp"

namespace swarmbox::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

std::string ReadFile(const fs::path& p) { return swarmbox::testing::ReadWholeFile(p.string()); }

// What `argv` prints in `container` (exit code must be 0).
std::string ExecOut(docker::DockerApi& api, const std::string& container, const std::vector<std::string>& argv) {
  faults::DockerExecCommandRunner runner(api, container);
  auto out = runner.Run(argv);
  EXPECT_TRUE(out) << out.error().ToString();
  if (!out) return {};
  EXPECT_EQ(out->exit_code, 0) << faults::CommandText(argv) << ": " << out->stderr_text;
  return out->stdout_text;
}

// Host pids of the processes named `comm` in the container `container_id` (its id in their
// cgroup paths, as Docker names them).
std::vector<std::string> HostProcessesOf(const std::string& container_id, const std::string& comm) {
  std::vector<std::string> pids;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/proc", ec)) {
    const std::string pid = entry.path().filename().string();
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    std::string name = ReadFile(entry.path() / "comm");
    if (!name.empty() && name.back() == '\n') name.pop_back();
    if (name != comm) continue;
    if (ReadFile(entry.path() / "cgroup").find(container_id) != std::string::npos) pids.push_back(pid);
  }
  return pids;
}

// The host's own iptables rules (its network namespace), every table; the run must succeed.
std::string HostIptables() {
  auto run = images::RunCapture({"iptables-save"});
  EXPECT_TRUE(run) << run.error().ToString();
  if (!run) return {};
  EXPECT_EQ(run->exit_code, 0) << run->err;
  return run->out;
}

TEST(FaultE2e, MeshImpairmentIsAppliedInTheSidecarsWithTheHostsMechanismAndRemoved) {
  swarmbox::testing::TrialOnDocker engine;
  const Status ready = engine.Prepare("fault-e2e", {SWARMBOX_PHYSICS_BIN, SWARMBOX_AGENT_BIN, SWARMBOX_NETEMD_BIN});
  ASSERT_TRUE(ready) << ready.error().ToString();
  docker::DockerApi& api = engine.api();

  dsl::TrialSpec spec = dsl::TrialSpec::Named("fault-e2e")
                            .Seed(17)
                            .World("worlds/open_field.yaml")
                            .Rtf(1.0)
                            .Drone("scout_1", "x500", {0, 0, 0})
                            .Drone("scout_2", "x500", {4, 0, 0})
                            .Mission({dsl::MissionKind::kPlan, "takeoff:3,hover:6,land", 40})
                            .Mesh("{delay_ms: 40, jitter_ms: 10, distribution: normal, loss: 0.05}")
                            .EndOn("event=plan_complete", dsl::Outcome::kSuccess, {}, "scout_2")
                            .EndOn("event=crash", dsl::Outcome::kFailure, "crash")
                            .Timeout(dsl::Duration::Seconds(60), dsl::Outcome::kTimeout, dsl::Duration::Seconds(240));
  spec.trials_dir = std::string(SWARMBOX_SOURCE_DIR) + "/trials";
  spec.radio.model = dsl::RadioModel::kNetem;  // the sidecars' impairment is what is inspected

  const fs::path out = engine.options().out_dir;
  const RunOptions& options = engine.options();
  const docker::LabelSelector& mine = engine.mine();

  // The trial runs on its own thread; this one inspects the sidecars while the agents fly.
  SteadyClock clock;
  Result<RunOutcome> run = Error(ErrorCode::kInternal, "not run");
  std::atomic<bool> done{false};
  std::thread runner([&] {
    run = RunTrialSpec(spec, api, clock, options);
    done.store(true);
  });

  const std::string sidecar_1 = ResourceName(spec.name, options.run_id, "scout_1-faults");
  const std::string sidecar_2 = ResourceName(spec.name, options.run_id, "scout_2-faults");
  const std::string agent_2 = ResourceName(spec.name, options.run_id, "scout_2");
  bool inspected = false;
  std::vector<std::string> daemons;  // host pids of the sidecars' swarmbox-netemd processes
  for (int i = 0; i < 600 && !done.load() && !inspected; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    auto state = api.InspectContainer(agent_2);
    if (!state || !state->state.running) continue;
    inspected = true;
    // The host's mechanism, as the runner detected it (same probe, on the sidecar's loopback).
    faults::DockerExecCommandRunner probe_runner(api, sidecar_1);
    auto mechanism = faults::DetectMechanism(probe_runner);
    ASSERT_TRUE(mechanism) << mechanism.error().ToString();
    for (const std::string& sidecar : {sidecar_1, sidecar_2}) {
      const std::string rules = ExecOut(api, sidecar, {"iptables", "-w", "-S"});
      const std::string qdisc_sim = ExecOut(api, sidecar, {"tc", "qdisc", "show", "dev", "eth0"});
      const std::string qdisc_mesh = ExecOut(api, sidecar, {"tc", "qdisc", "show", "dev", "eth1"});
      // The sim link is untouched: no rule names eth0, no impairing qdisc on it.
      EXPECT_THAT(rules, Not(HasSubstr("eth0"))) << sidecar;
      EXPECT_THAT(qdisc_sim, Not(HasSubstr("netem")));
      EXPECT_THAT(qdisc_sim, Not(HasSubstr("tbf")));
      if (*mechanism == faults::Mechanism::kUserspace) {
        EXPECT_THAT(rules, HasSubstr("-A OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT")) << rules;
        EXPECT_THAT(rules, HasSubstr("-A SWARMBOX-RADIO-OUT -j NFQUEUE --queue-num 0 --queue-bypass")) << rules;
        EXPECT_THAT(rules, HasSubstr("-A INPUT -i eth1 -j SWARMBOX-RADIO-IN")) << rules;
        // iptables prints the kernel's 32-bit fixed-point probability (0.04999999981 for 0.05).
        const auto at = rules.find("-A SWARMBOX-RADIO-IN -m statistic --mode random --probability ");
        ASSERT_NE(at, std::string::npos) << rules;
        const double p = std::stod(rules.substr(at + std::string("-A SWARMBOX-RADIO-IN -m statistic --mode random --probability ").size()));
        EXPECT_NEAR(p, 0.05, 1e-6) << rules;
        // The delayer runs in the sidecar (its pidfile is there), as a process of the sidecar.
        auto pidfile = api.GetArchive(sidecar, "/run/swarmbox-netemd-0.pid");
        EXPECT_TRUE(pidfile) << sidecar << ": " << (pidfile ? "" : pidfile.error().ToString());
        auto info = api.InspectContainer(sidecar);
        ASSERT_TRUE(info) << info.error().ToString();
        const auto pids = HostProcessesOf(info->id, "swarmbox-netemd");
        EXPECT_GE(pids.size(), 2u) << sidecar << ": the sleeping init and the delayer";
        daemons.insert(daemons.end(), pids.begin(), pids.end());
      } else {
        EXPECT_THAT(qdisc_mesh, HasSubstr("netem")) << qdisc_mesh;
        EXPECT_THAT(qdisc_mesh, HasSubstr("delay 40ms")) << qdisc_mesh;
      }
    }
  }
  runner.join();
  ASSERT_TRUE(inspected) << "the agents never ran";
  ASSERT_TRUE(run) << run.error().ToString();
  EXPECT_EQ(run->result.verdict.outcome, dsl::Outcome::kSuccess) << run->result.verdict.ToString();

  const std::string events = ReadFile(fs::path(run->trial_dir) / "events.jsonl");
  EXPECT_THAT(events, HasSubstr("{\"type\":\"mechanism\",\"host\":\"fault-e2e-local\",\"mechanism\":\""));
  for (const std::string d : {"scout_1", "scout_2"}) {
    EXPECT_THAT(events, HasSubstr("{\"type\":\"mesh\",\"phase\":\"applied\",\"node\":\"" + d + "\""));
    EXPECT_THAT(events, HasSubstr("{\"type\":\"mesh\",\"phase\":\"removed\",\"node\":\"" + d + "\""));
  }
  EXPECT_THAT(events, Not(HasSubstr("\"phase\":\"failed\"")));
  // Raft ran over the impaired mesh.
  EXPECT_THAT(events, HasSubstr("\"event\":\"leader_elected\""));

  // The mesh rules were not undone command by command: they went with the sidecars' network
  // namespaces, and the delay daemons with the sidecars. Nothing of them is on the host: no
  // SWARMBOX chain or NFQUEUE rule in its own iptables, no daemon left running.
  EXPECT_THAT(events, HasSubstr("\"note\":\"with the sidecar's network namespace\""));
  const std::string host_rules = HostIptables();
  EXPECT_THAT(host_rules, Not(HasSubstr("SWARMBOX-"))) << host_rules;
  EXPECT_THAT(host_rules, Not(HasSubstr("NFQUEUE"))) << host_rules;
  for (const std::string& pid : daemons) {
    std::string comm = ReadFile(fs::path("/proc") / pid / "comm");
    EXPECT_THAT(comm, Not(HasSubstr("swarmbox-netemd"))) << "pid " << pid << " still runs";
  }

  // Nothing labelled with the run is left.
  auto containers = api.ListContainers(mine, /*all=*/true);
  ASSERT_TRUE(containers);
  EXPECT_TRUE(containers->empty()) << containers->size() << " containers left";
  auto networks = api.ListNetworks(mine);
  ASSERT_TRUE(networks);
  EXPECT_TRUE(networks->empty()) << networks->size() << " networks left";
  fs::remove_all(out);
}

}  // namespace
}  // namespace swarmbox::runner
