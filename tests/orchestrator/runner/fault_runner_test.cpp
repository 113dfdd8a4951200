// Faults carried out by the runner, against FakeDockerApi (exec answered from a script, kill/pause/
// restart modelled): the fault sidecars (one per agent, owning its network namespace, the only
// container with NET_ADMIN), the mechanism detected through a sidecar, network.mesh applied before
// the agents start and left to the sidecars' namespaces at teardown (no undo command: the rules
// die with the namespace), fault windows ending mid-trial undone explicitly, timeline triggers (sim time, log events), partitions,
// process faults on the Raft leader, refusals and failures, and that nothing is left on any path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

#include "support/fake_clock.hpp"
#include "support/fake_docker_api.hpp"
#include "support/files.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/runner/runner.hpp"

namespace swarmbox::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

std::string ReadFile(const fs::path& p) { return swarmbox::testing::ReadWholeFile(p.string()); }

constexpr char kRun[] = "20261121-160000-f00d";
constexpr char kProbe[] = "tc qdisc replace dev lo root netem delay 0ms";

std::string Name(const std::string& component) { return std::string("mini-") + kRun + "-" + component; }

// Index of the first call starting with `prefix`; calls.size() when none.
std::size_t IndexOf(const std::vector<std::string>& calls, const std::string& prefix) {
  for (std::size_t i = 0; i < calls.size(); ++i) {
    if (calls[i].rfind(prefix, 0) == 0) return i;
  }
  return calls.size();
}
// Index of the call that is exactly `call`; calls.size() when none.
std::size_t IndexOfExact(const std::vector<std::string>& calls, const std::string& call) {
  for (std::size_t i = 0; i < calls.size(); ++i) {
    if (calls[i] == call) return i;
  }
  return calls.size();
}
std::size_t LastIndexOfExact(const std::vector<std::string>& calls, const std::string& call) {
  for (std::size_t i = calls.size(); i-- > 0;) {
    if (calls[i] == call) return i;
  }
  return calls.size();
}
std::size_t LastIndexOf(const std::vector<std::string>& calls, const std::string& prefix) {
  for (std::size_t i = calls.size(); i-- > 0;) {
    if (calls[i].rfind(prefix, 0) == 0) return i;
  }
  return calls.size();
}
std::vector<std::string> Matching(const std::vector<std::string>& calls, const std::string& needle) {
  std::vector<std::string> out;
  for (const auto& c : calls) {
    if (c.find(needle) != std::string::npos) out.push_back(c);
  }
  return out;
}

class FaultRunnerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() /
           ("swarmbox-fault-runner-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(out_);
    spec_ = dsl::TrialSpec::Named("mini")
                .Seed(9)
                .World("worlds/open_field.yaml")
                .Drone("scout_1", "x500", {0, 0, 0})
                .Drone("scout_2", "x500", {3, 0, 0})
                .Mission({dsl::MissionKind::kPlan, "takeoff:5,hover:10,land", 40})
                .EndOn("event=done", dsl::Outcome::kSuccess)
                .Timeout(dsl::Duration::Seconds(60), dsl::Outcome::kTimeout, dsl::Duration::Seconds(600));
    spec_.trials_dir = std::string(SWARMBOX_SOURCE_DIR) + "/trials";
    // Faults carried out by the runner itself: the netem model (channel_runner_test.cpp has the
    // channel's, where the physics server schedules them).
    spec_.radio.model = dsl::RadioModel::kNetem;
    options_.out_dir = out_.string();
    options_.run_id = kRun;
    options_.images = {"swarmbox/physics:test", "swarmbox/agent:test"};
    options_.faults_image = "swarmbox/faults:test";
    // A host of its own per test run: the mechanism is cached per host for the whole process.
    static int runs = 0;
    options_.host = "fake-host-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
                    "-" + std::to_string(++runs);
    options_.poll = std::chrono::milliseconds(5);
    // This "kernel" has no sch_netem: the userspace mechanism.
    api_.exec_answers[kProbe] = {{}, {"Error: Specified qdisc kind is unknown."}, 2};
    api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready"};
  }
  void TearDown() override { fs::remove_all(out_); }

  RunOutcome Run(double clock_step = 0.001) {
    testing::FakeClock clock(1000, clock_step);
    auto run = RunTrialSpec(spec_, api_, clock, options_);
    EXPECT_TRUE(run) << run.error().ToString();
    if (!run) return {};
    return *run;
  }
  void ExpectNothingLeft() {
    EXPECT_TRUE(api_.Containers().empty());
    EXPECT_TRUE(api_.Networks().empty());
  }
  std::string Events(const RunOutcome& run) { return ReadFile(fs::path(run.trial_dir) / "events.jsonl"); }

  fs::path out_;
  dsl::TrialSpec spec_;
  RunOptions options_;
  testing::FakeDockerApi api_;
};

TEST_F(FaultRunnerTest, MeshImpairmentIsAppliedFromSidecarsBeforeTheAgentsStartAndGoesWithTheirNamespaces) {
  spec_.Mesh("{delay_ms: 100, jitter_ms: 20, loss: 0.05}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=3.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  ExpectNothingLeft();

  // One sidecar per agent: the faults image, the drone's addresses, NET_ADMIN alone; the agent
  // joins its namespace and stays unprivileged.
  std::map<std::string, docker::ContainerSpec> created;
  for (const auto& c : api_.Created()) created[c.name] = c;
  for (const std::string d : {"scout_1", "scout_2"}) {
    ASSERT_EQ(created.count(Name(d + "-faults")), 1u) << d;
    const docker::ContainerSpec& sc = created[Name(d + "-faults")];
    EXPECT_EQ(sc.image, "swarmbox/faults:test");
    EXPECT_EQ(sc.cap_add, std::vector<std::string>{"NET_ADMIN"});
    EXPECT_EQ(sc.cap_drop, std::vector<std::string>{"ALL"});
    EXPECT_EQ(sc.networks.size(), 2u);
    EXPECT_EQ(sc.labels.at("swarmbox.run"), kRun);
    EXPECT_EQ(sc.labels.at("swarmbox.component"), d + "-faults");
    EXPECT_EQ(sc.entrypoint, std::vector<std::string>{"/usr/bin/swarmbox-netemd"});
    EXPECT_EQ(sc.cmd, std::vector<std::string>{"sleep"});
    const docker::ContainerSpec& agent = created[Name(d)];
    EXPECT_THAT(agent.network_mode, ::testing::StartsWith("container:"));
    EXPECT_TRUE(agent.networks.empty());
    EXPECT_TRUE(agent.cap_add.empty());
  }
  EXPECT_TRUE(created[Name("physics")].cap_add.empty());

  const std::vector<std::string> calls = api_.Calls();
  // Order: sidecars start, the probe (once, in the first sidecar), the mesh rules in every
  // sidecar, then the agents start.
  const std::size_t probe = IndexOf(calls, "exec " + Name("scout_1-faults") + " " + kProbe);
  ASSERT_LT(probe, calls.size());
  EXPECT_EQ(Matching(calls, kProbe).size(), 1u);
  EXPECT_LT(IndexOfExact(calls, "start " + Name("scout_2-faults")), probe);
  for (const std::string d : {"scout_1", "scout_2"}) {
    const std::string in = "exec " + Name(d + "-faults") + " ";
    const std::size_t hook = IndexOf(calls, in + "iptables -w -I INPUT -i eth1 -j SWARMBOX-RADIO-IN");
    ASSERT_LT(hook, calls.size()) << d;
    EXPECT_LT(probe, hook);
    EXPECT_LT(hook, IndexOfExact(calls, "start " + Name("scout_1")));
    EXPECT_LT(IndexOf(calls, in + "/usr/bin/swarmbox-netemd run --queue 0 --delay-us 100000 --jitter-us 20000"),
              IndexOfExact(calls, "start " + Name(d)));
    EXPECT_LT(IndexOf(calls, in + "iptables -w -A SWARMBOX-RADIO-IN -m statistic --mode random --probability 0.05 -j DROP"),
              calls.size());
    // Teardown: nothing is exec'd in the sidecar once its agent stopped (no iptables -D, no
    // `swarmbox-netemd stop`): the rules and the daemons go when the sidecar stops, after the agent.
    const std::size_t agent_stop = IndexOfExact(calls, "stop " + Name(d));
    const std::size_t sidecar_stop = IndexOfExact(calls, "stop " + Name(d + "-faults"));
    ASSERT_LT(agent_stop, calls.size()) << d;
    ASSERT_LT(sidecar_stop, calls.size()) << d;
    EXPECT_LT(agent_stop, sidecar_stop);
    EXPECT_LT(LastIndexOf(calls, in), agent_stop) << ::testing::PrintToString(calls);
    EXPECT_THAT(Matching(calls, in + "/usr/bin/swarmbox-netemd stop"), ::testing::IsEmpty());
    EXPECT_THAT(Matching(calls, in + "iptables -w -D "), ::testing::IsEmpty());
  }
  // The sim link (eth0) is never touched.
  EXPECT_THAT(Matching(calls, "eth0"), ::testing::IsEmpty());

  const std::string events = Events(run);
  EXPECT_THAT(events, HasSubstr("{\"type\":\"mechanism\",\"host\":\"" + options_.host +
                                "\",\"mechanism\":\"userspace-nfqueue\",\"detected\":true"));
  for (const std::string d : {"scout_1", "scout_2"}) {
    EXPECT_THAT(events, HasSubstr("{\"type\":\"mesh\",\"phase\":\"applied\",\"node\":\"" + d + "\""));
    EXPECT_THAT(events, HasSubstr("{\"type\":\"mesh\",\"phase\":\"removed\",\"node\":\"" + d + "\""));
  }
  EXPECT_THAT(events, HasSubstr("\"mechanism\":\"userspace-nfqueue\",\"spec\":\"delay_ms=100 jitter_ms=20 loss=0.05\""));
  EXPECT_THAT(events, HasSubstr("\"spec\":\"delay_ms=100 jitter_ms=20 loss=0.05\",\"note\":\"with the sidecar's network namespace\"}"));
}

TEST_F(FaultRunnerTest, MechanismIsDetectedOncePerHost) {
  spec_.Mesh("{loss: 0.1}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.000 node=physics event=done"};
  RunOutcome first = Run();
  EXPECT_EQ(first.result.verdict.outcome, dsl::Outcome::kSuccess) << first.result.verdict.ToString();
  options_.run_id = "20261121-160001-f00e";
  RunOutcome second = Run();
  EXPECT_EQ(second.result.verdict.outcome, dsl::Outcome::kSuccess) << second.result.verdict.ToString();
  EXPECT_EQ(Matching(api_.Calls(), kProbe).size(), 1u);
  EXPECT_THAT(Events(second), HasSubstr("\"mechanism\":\"userspace-nfqueue\",\"detected\":false"));
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, SpecTheMechanismCannotHonourIsRefusedBeforeAnyAgentStarts) {
  spec_.Mesh("{delay_ms: 20, loss: 0.1, loss_correlation: 0.5}");
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kError);
  EXPECT_THAT(run.result.verdict.reason, HasSubstr("'loss_correlation' cannot be honoured on this host"));
  const auto calls = api_.Calls();
  EXPECT_EQ(IndexOfExact(calls, "start " + Name("scout_1")), calls.size());
  EXPECT_EQ(IndexOfExact(calls, "start " + Name("scout_2")), calls.size());
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, PartitionAtSimTimeIsAppliedInEverySidecarAndHealed) {
  spec_.Fault("{name: split, at: 2s, duration: 1s, partition: {groups: [[scout_1], [scout_2]]}}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.000 node=physics event=tick",
                                   "t=2.500 node=physics event=tick", "t=4.000 node=physics event=tick",
                                   "t=5.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  ExpectNothingLeft();
  const auto calls = api_.Calls();
  for (const std::string d : {"scout_1", "scout_2"}) {
    const std::string in = "exec " + Name(d + "-faults") + " iptables -w ";
    const std::size_t hook = IndexOf(calls, in + "-I INPUT -i eth1 -j SWARMBOX-PART-0");
    const std::size_t heal = IndexOf(calls, in + "-D INPUT -i eth1 -j SWARMBOX-PART-0");
    ASSERT_LT(hook, calls.size()) << d;
    ASSERT_LT(heal, calls.size()) << d;
    EXPECT_LT(hook, heal);
    EXPECT_LT(heal, IndexOfExact(calls, "stop " + Name(d)));  // healed at 3 s, not at teardown
  }
  // scout_1 drops what comes from scout_2's mesh address and the other way round.
  EXPECT_EQ(Matching(calls, "SWARMBOX-PART-0 -s ").size(), 2u);
  const std::string events = Events(run);
  EXPECT_THAT(events, HasSubstr("\"phase\":\"applied\",\"fault\":\"split\",\"kind\":\"partition\",\"start\":\"at 2s\",\"t_sim_s\":2.5,"));
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"split\",\"kind\":\"partition\",\"start\":\"at 2s\",\"t_sim_s\":4,"));
  EXPECT_THAT(events, HasSubstr("\"mechanism\":\"iptables\""));
}

// The fault records of events.jsonl, parsed, in file order.
std::vector<yaml::Node> FaultRecords(const std::string& events, const std::string& fault) {
  std::vector<yaml::Node> out;
  std::istringstream lines(events);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("\"type\":\"fault\"") == std::string::npos) continue;
    auto doc = yaml::Parse(line, "events.jsonl");
    if (doc && doc->Find("fault") != nullptr && doc->Find("fault")->scalar() == fault) out.push_back(*doc);
  }
  return out;
}

double NumberOf(const yaml::Node& doc, std::string_view key) {
  const yaml::Node* n = doc.Find(key);
  return n != nullptr ? yaml::ScalarAsDouble(n->scalar()).value_or(-1) : -1;
}

TEST_F(FaultRunnerTest, AFaultIsRecordedRequestedThenAppliedOnceEveryTargetConfirmedIt) {
  // scout_2's sidecar takes 7 s to install the partition's hook (a busy engine): `applied` comes
  // after it, with the time of the last confirmation; `requested` before anything was run.
  spec_.Fault("{name: split, at: 2s, duration: 1s, partition: {groups: [[scout_1], [scout_2]]}}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.000 node=physics event=tick",
                                   "t=2.500 node=physics event=tick", "t=4.000 node=physics event=tick",
                                   "t=5.000 node=physics event=done"};
  testing::FakeClock clock;
  const std::string slow = "exec " + Name("scout_2-faults") + " iptables -w -I INPUT -i eth1 -j SWARMBOX-PART-0";
  std::atomic<bool> slow_done{false};
  api_.on_exec = [&](const std::string& call) {
    if (call == slow) {
      clock.Jump(7.0);
      slow_done = true;
    }
  };
  auto run = RunTrialSpec(spec_, api_, clock, options_);
  ASSERT_TRUE(run) << run.error().ToString();
  EXPECT_EQ(run->result.verdict.outcome, dsl::Outcome::kSuccess) << run->result.verdict.ToString();
  EXPECT_TRUE(slow_done);
  const auto records = FaultRecords(ReadFile(fs::path(run->trial_dir) / "events.jsonl"), "split");
  std::vector<std::string> phases;
  for (const yaml::Node& r : records) phases.push_back(r.Find("phase")->scalar());
  ASSERT_EQ(phases, (std::vector<std::string>{"requested", "applied", "remove_requested", "removed"}));
  const yaml::Node& requested = records[0];
  const yaml::Node& applied = records[1];
  // Both name the targets and the mechanism, each has its own sim and wall time.
  for (const yaml::Node* r : {&requested, &applied}) {
    EXPECT_EQ(r->Find("targets")->items().size(), 2u);
    EXPECT_EQ(r->Find("mechanism")->scalar(), "iptables");
    EXPECT_GE(NumberOf(*r, "t_sim_s"), 2.5);
  }
  EXPECT_GE(NumberOf(applied, "wall_s"), NumberOf(requested, "wall_s") + 7.0);
  EXPECT_EQ(NumberOf(applied, "requested_wall_s"), NumberOf(requested, "wall_s"));
  EXPECT_EQ(NumberOf(applied, "requested_t_sim_s"), NumberOf(requested, "t_sim_s"));
  EXPECT_EQ(requested.Find("requested_wall_s"), nullptr);
  // The removal likewise: asked for at 4 s of simulated time, done after.
  EXPECT_GE(NumberOf(records[3], "wall_s"), NumberOf(records[2], "wall_s"));
  EXPECT_EQ(NumberOf(records[3], "requested_wall_s"), NumberOf(records[2], "wall_s"));
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, AFaultThatFailsIsRecordedRequestedThenFailed) {
  spec_.Fault("{name: split, at: 2s, duration: 1s, partition: {groups: [[scout_1], [scout_2]]}}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=2.500 node=physics event=tick",
                                   "t=5.000 node=physics event=done"};
  api_.exec_answers["iptables -w -I INPUT -i eth1 -j SWARMBOX-PART-0"] = {{}, {"iptables: No chain"}, 1};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kError);
  const auto records = FaultRecords(Events(run), "split");
  ASSERT_GE(records.size(), 2u);
  EXPECT_EQ(records[0].Find("phase")->scalar(), "requested");
  EXPECT_EQ(records[1].Find("phase")->scalar(), "failed");
  EXPECT_THAT(records[1].Find("error")->scalar(), HasSubstr("No chain"));
  for (const yaml::Node& r : records) EXPECT_NE(r.Find("phase")->scalar(), "applied");
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, KillingTheRaftLeaderOnAnEventIsNotACrashAndIsUndoneAfterItsDuration) {
  // No network faults: no sidecars, the agents keep their own namespaces.
  spec_.Fault("{name: kill_leader, on: \"event=leader_elected\", duration: 200ms, kill: raft_leader}");
  api_.scripts["scout_1"].lines = {"t=1.0 node=scout_1 event=leader_elected term=2 leader=scout_2"};
  api_.scripts["scout_2"].lines = {"t=1.0 node=scout_2 event=leader_elected term=2 leader=scout_2"};
  api_.scripts["scout_2"].restart_lines = {"t=4.0 node=scout_2 event=rejoined", "t=4.1 node=scout_2 event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_EQ(run.result.verdict.source, "scout_2");
  ExpectNothingLeft();
  const auto calls = api_.Calls();
  EXPECT_EQ(IndexOfExact(calls, "create " + Name("scout_1-faults")), calls.size());
  const std::size_t kill = IndexOf(calls, "kill " + Name("scout_2") + " SIGKILL");
  ASSERT_LT(kill, calls.size());
  EXPECT_LT(kill, LastIndexOfExact(calls, "start " + Name("scout_2")));
  EXPECT_EQ(Matching(calls, "kill ").size(), 1u);  // fired once, on the first election line
  // The log was followed again from the first new line: nothing twice.
  const std::string log = ReadFile(fs::path(run.trial_dir) / "logs" / "scout_2.log");
  EXPECT_EQ(log, "t=1.0 node=scout_2 event=leader_elected term=2 leader=scout_2\n"
                 "t=4.0 node=scout_2 event=rejoined\nt=4.1 node=scout_2 event=done\n");
  const std::string events = Events(run);
  EXPECT_THAT(events, HasSubstr("\"phase\":\"requested\",\"fault\":\"kill_leader\",\"kind\":\"kill\",\"start\":\"on event=leader_elected\""));
  EXPECT_THAT(events, HasSubstr("\"phase\":\"applied\",\"fault\":\"kill_leader\",\"kind\":\"kill\",\"start\":\"on event=leader_elected\""));
  EXPECT_THAT(events, HasSubstr("\"targets\":[\"scout_2\"],\"mechanism\":\"docker\",\"spec\":\"signal=SIGKILL duration=200ms\"}"));
  EXPECT_THAT(events, HasSubstr("\"targets\":[\"scout_2\"],\"mechanism\":\"docker\",\"spec\":\"signal=SIGKILL duration=200ms\",\"requested_t_sim_s\":"));
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"kill_leader\""));
}

TEST_F(FaultRunnerTest, RestartFollowsTheNewRunsLog) {
  spec_.Fault("{name: reboot, at: 2s, restart: scout_1}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=2.500 node=physics event=tick"};
  api_.scripts["scout_1"].lines = {"t=0.5 node=scout_1 event=takeoff"};
  api_.scripts["scout_1"].restart_lines = {"t=3.0 node=scout_1 event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_LT(IndexOf(api_.Calls(), "restart " + Name("scout_1") + " 10"), api_.Calls().size());
  EXPECT_EQ(ReadFile(fs::path(run.trial_dir) / "logs" / "scout_1.log"),
            "t=0.5 node=scout_1 event=takeoff\nt=3.0 node=scout_1 event=done\n");
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, AFaultStillActiveAtTheEndIsUndoneBeforeTheContainersStop) {
  spec_.Fault("{name: freeze, at: 1s, pause: scout_2}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.500 node=physics event=tick",
                                   "t=2.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  const auto calls = api_.Calls();
  const std::size_t pause = IndexOfExact(calls, "pause " + Name("scout_2"));
  const std::size_t unpause = IndexOfExact(calls, "unpause " + Name("scout_2"));
  ASSERT_LT(pause, calls.size());
  ASSERT_LT(unpause, calls.size());
  EXPECT_LT(pause, unpause);
  EXPECT_LT(unpause, IndexOfExact(calls, "stop " + Name("scout_2")));
  EXPECT_THAT(Events(run), HasSubstr("\"phase\":\"removed\",\"fault\":\"freeze\""));
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, AFaultThatCannotBeCarriedOutEndsTheTrialWithErrorAndTearsDown) {
  spec_.Mesh("{loss: 0.02}");
  spec_.Fault("{name: kill_leader, at: 1s, kill: raft_leader}");  // nobody was elected
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.500 node=physics event=tick",
                                   "t=9.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kError);
  EXPECT_THAT(run.result.verdict.reason, HasSubstr("fault kill_leader (kill) could not be applied"));
  EXPECT_THAT(Events(run), HasSubstr("\"phase\":\"failed\",\"fault\":\"kill_leader\""));
  EXPECT_THAT(Events(run), HasSubstr("{\"type\":\"mesh\",\"phase\":\"removed\",\"node\":\"scout_1\""));
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, InterruptedRunLeavesNothingAndExecsNoUndoInTheSidecars) {
  spec_.Mesh("{delay_ms: 50}");
  spec_.Fault("{name: fade, at: 1s, radio: {target: scout_1, loss: 0.3}}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.500 node=physics event=tick"};
  std::atomic<bool> interrupted{false};
  options_.interrupted = &interrupted;
  // Ctrl-C once the radio fault is in place (the exec of its loss rule).
  api_.exec_answers["iptables -w -A SWARMBOX-RADIO-IN -m statistic --mode random --probability 0.3 -j DROP"] = {};
  testing::FakeClock clock(1000, 0.001);
  std::thread stopper([&] {
    for (int i = 0; i < 2000 && !interrupted.load(); ++i) {
      if (!Matching(api_.Calls(), "--probability 0.3").empty()) interrupted.store(true);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });
  auto run = RunTrialSpec(spec_, api_, clock, options_);
  stopper.join();
  ASSERT_TRUE(run) << run.error().ToString();
  EXPECT_EQ(run->result.verdict.outcome, dsl::Outcome::kError);
  EXPECT_THAT(run->result.verdict.reason, HasSubstr("interrupted"));
  const auto calls = api_.Calls();
  // Neither the fault nor the mesh rules were undone command by command: nothing was exec'd in
  // a sidecar once the agents stopped (scout_1's -D and `netemd stop` calls are the fault's
  // apply, which swaps the mesh rules for the fault's), and the sidecars (with them their
  // namespaces) were stopped and removed.
  for (const std::string d : {"scout_1", "scout_2"}) {
    const std::string in = "exec " + Name(d + "-faults") + " ";
    const std::size_t agent_stop = IndexOfExact(calls, "stop " + Name(d));
    ASSERT_LT(agent_stop, calls.size()) << d;
    EXPECT_LT(LastIndexOf(calls, in), agent_stop) << d << ": " << ::testing::PrintToString(calls);
    EXPECT_LT(IndexOfExact(calls, "remove " + Name(d + "-faults")), calls.size()) << d;
  }
  EXPECT_THAT(Matching(calls, "exec " + Name("scout_2-faults") + " iptables -w -D "), ::testing::IsEmpty());
  const std::string events = Events(*run);
  EXPECT_THAT(events, HasSubstr("\"phase\":\"applied\",\"fault\":\"fade\""));
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"fade\""));
  EXPECT_THAT(events, HasSubstr("\"spec\":\"loss=0.3\",\"note\":\"with the sidecar's network namespace\",\"requested_t_sim_s\":"));
  EXPECT_THAT(events, HasSubstr("{\"type\":\"mesh\",\"phase\":\"removed\",\"node\":\"scout_1\""));
  EXPECT_THAT(events, Not(HasSubstr("\"phase\":\"failed\"")));
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, ARadioFaultWindowEndingMidTrialIsUndoneInTheSidecarWhileTheTrialGoesOn) {
  spec_.Mesh("{delay_ms: 50}");
  spec_.Fault("{name: fade, at: 1s, duration: 1s, radio: {target: scout_1, loss: 0.3}}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.500 node=physics event=tick",
                                   "t=3.000 node=physics event=tick", "t=4.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  const auto calls = api_.Calls();
  const std::string in = "exec " + Name("scout_1-faults") + " ";
  const std::size_t fade = IndexOf(calls, in + "iptables -w -A SWARMBOX-RADIO-IN -m statistic --mode random --probability 0.3");
  ASSERT_LT(fade, calls.size()) << ::testing::PrintToString(calls);
  // At 3 s the fault's rules are replaced by the mesh rules again (its chain unhooked, its
  // daemon stopped, the mesh's started), all before the agent stops.
  const std::size_t agent_stop = IndexOfExact(calls, "stop " + Name("scout_1"));
  const std::size_t unhook = IndexOf(calls, in + "iptables -w -D INPUT -i eth1 -j SWARMBOX-RADIO-IN");
  const std::size_t daemon_stop = IndexOf(calls, in + "/usr/bin/swarmbox-netemd stop");
  ASSERT_LT(unhook, calls.size()) << ::testing::PrintToString(calls);
  ASSERT_LT(daemon_stop, calls.size()) << ::testing::PrintToString(calls);
  EXPECT_LT(fade, unhook);
  EXPECT_LT(unhook, agent_stop);
  EXPECT_LT(daemon_stop, agent_stop);
  EXPECT_LT(LastIndexOf(calls, in + "/usr/bin/swarmbox-netemd run"), agent_stop);
  // The other drone's radio was never touched after the set-up.
  EXPECT_THAT(Matching(calls, "exec " + Name("scout_2-faults") + " iptables -w -D "), ::testing::IsEmpty());
  const std::string events = Events(run);
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"fade\",\"kind\":\"radio\",\"start\":\"at 1s\",\"t_sim_s\":3,"));
  // Removed in the sidecar, not with the namespace: no note on the fault's record.
  EXPECT_THAT(events, HasSubstr("\"spec\":\"loss=0.3 duration=1s\"}"));
  EXPECT_THAT(events, Not(HasSubstr("\"phase\":\"failed\"")));
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, APartitionStillActiveAtTheEndGoesWithTheSidecarsNamespaces) {
  spec_.Fault("{name: split, at: 2s, partition: {groups: [[scout_1], [scout_2]]}}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=2.500 node=physics event=tick",
                                   "t=3.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  const auto calls = api_.Calls();
  for (const std::string d : {"scout_1", "scout_2"}) {
    const std::string in = "exec " + Name(d + "-faults") + " iptables -w ";
    EXPECT_LT(IndexOf(calls, in + "-I INPUT -i eth1 -j SWARMBOX-PART-0"), calls.size()) << d;
    EXPECT_THAT(Matching(calls, in + "-D "), ::testing::IsEmpty()) << d;
    EXPECT_THAT(Matching(calls, in + "-X "), ::testing::IsEmpty()) << d;
    EXPECT_LT(IndexOfExact(calls, "stop " + Name(d)), IndexOfExact(calls, "stop " + Name(d + "-faults"))) << d;
  }
  const std::string events = Events(run);
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"split\""));
  EXPECT_THAT(events, HasSubstr("\"mechanism\":\"iptables\",\"spec\":\"groups=[[scout_1], [scout_2]] oneway=false\",\"note\":\"with the sidecar's network namespace\",\"requested_t_sim_s\":"));
  ExpectNothingLeft();
}

// Sensor and environment faults: `swarmbox-physics --send-command` exec'd in the physics
// container (no sidecars: they touch no network), exit code checked, mechanism physics-command.
constexpr char kSend[] =
    "/usr/local/bin/swarmbox-physics --sim-interface eth0 --domain 0 --middleware cyclonedds --send-command ";

TEST_F(FaultRunnerTest, GpsDropoutIsSentToThePhysicsServerWithItsDuration) {
  spec_.Fault("{name: gps_loss, at: 1s, duration: 1500ms, gps_dropout: scout_1}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.500 node=physics event=clock",
                                   "t=3.000 node=physics event=clock", "t=3.500 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  const auto calls = api_.Calls();
  const std::string exec = "exec " + Name("physics") + " " + kSend + "scout_1 gps_dropout 1.5";
  EXPECT_LT(IndexOfExact(calls, exec), calls.size()) << ::testing::PrintToString(calls);
  // Once: the server restores the fix itself after 1.5 simulated s, nothing is sent at removal.
  EXPECT_EQ(Matching(calls, "--send-command").size(), 1u);
  EXPECT_THAT(calls, Not(::testing::Contains(HasSubstr("-faults"))));
  const std::string events = Events(run);
  EXPECT_THAT(events, HasSubstr("\"phase\":\"applied\",\"fault\":\"gps_loss\",\"kind\":\"gps_dropout\",\"start\":\"at 1s\""));
  EXPECT_THAT(events, HasSubstr("\"targets\":[\"scout_1\"],\"mechanism\":\"physics-command\""));
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"gps_loss\""));
  EXPECT_THAT(events, Not(HasSubstr("\"phase\":\"failed\"")));
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, GpsDegradeIsSentWithItsDurationAndAccuraciesToEveryTarget) {
  spec_.Fault("{name: bad_fix, at: 1s, duration: 4s, gps_degrade: {target: all, h_acc_m: 5, v_acc_m: 8.5}}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.500 node=physics event=clock",
                                   "t=5.500 node=physics event=clock", "t=6.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  const auto calls = api_.Calls();
  const std::string in = "exec " + Name("physics") + " " + kSend;
  for (const std::string d : {"scout_1", "scout_2"}) {
    EXPECT_LT(IndexOfExact(calls, in + d + " gps_degrade 4 5 8.5"), calls.size()) << ::testing::PrintToString(calls);
  }
  // Once per drone: the server restores the airframe's accuracy itself after 4 simulated s.
  EXPECT_EQ(Matching(calls, "--send-command").size(), 2u);
  const std::string events = Events(run);
  EXPECT_THAT(events, HasSubstr("\"phase\":\"applied\",\"fault\":\"bad_fix\",\"kind\":\"gps_degrade\""));
  EXPECT_THAT(events, HasSubstr("\"mechanism\":\"physics-command\",\"spec\":\"h_acc_m=5 v_acc_m=8.5 duration=4s\""));
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"bad_fix\""));
  EXPECT_THAT(events, Not(HasSubstr("\"phase\":\"failed\"")));
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, ImuBiasIsTakenBackByTheNegatedJumpAndAGustCarriesItsVector) {
  spec_.Fault("{name: bias, at: 1s, duration: 1s, imu_bias: {target: all, accel_m_s2: [0.3, 0, 0], gyro_rad_s: [0, 0, 0.02]}}");
  spec_.Fault("{name: gust, at: 1s, duration: 5s, wind_gust: {speed_m_s: 12, direction_deg: 270, vertical_m_s: -1.5}}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.500 node=physics event=clock",
                                   "t=2.500 node=physics event=clock", "t=3.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  const auto calls = api_.Calls();
  const std::string in = "exec " + Name("physics") + " " + kSend;
  for (const std::string d : {"scout_1", "scout_2"}) {
    const std::size_t jump = IndexOfExact(calls, in + d + " imu_bias_jump 0.3 0 0 0 0 0.02");
    const std::size_t back = IndexOfExact(calls, in + d + " imu_bias_jump -0.3 0 0 0 0 -0.02");
    ASSERT_LT(jump, calls.size()) << ::testing::PrintToString(calls);
    ASSERT_LT(back, calls.size()) << ::testing::PrintToString(calls);
    EXPECT_LT(jump, back);
  }
  // From the west (270 deg) blows towards +x (east), ENU; the world as target is "-". Still
  // active at the end: the server drops it with the run, nothing is sent.
  EXPECT_LT(IndexOfExact(calls, in + "- wind_gust 12 0 -1.5 5"), calls.size()) << ::testing::PrintToString(calls);
  EXPECT_EQ(Matching(calls, "wind_gust").size(), 1u);
  const std::string events = Events(run);
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"bias\""));
  EXPECT_THAT(events, HasSubstr("\"phase\":\"applied\",\"fault\":\"gust\",\"kind\":\"wind_gust\""));
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"gust\""));
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, APhysicsCommandThatFailsEndsTheTrialWithItsMessage) {
  spec_.Fault("{name: gps_loss, at: 1s, duration: 1s, gps_dropout: scout_2}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.500 node=physics event=clock",
                                   "t=9.000 node=physics event=done"};
  api_.exec_answers[std::string(kSend) + "scout_2 gps_dropout 1"] = {
      {}, {"swarmbox-physics: no physics server matched on sim/world_command"}, 3};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kError);
  EXPECT_THAT(run.result.verdict.reason, HasSubstr("fault gps_loss (gps_dropout) could not be applied"));
  EXPECT_THAT(run.result.verdict.reason, HasSubstr("no physics server matched"));
  const std::string events = Events(run);
  EXPECT_THAT(events, HasSubstr("\"phase\":\"failed\",\"fault\":\"gps_loss\""));
  EXPECT_THAT(events, HasSubstr("\"mechanism\":\"physics-command\""));
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, WithoutFaultsNoSidecarIsCreated) {
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_THAT(api_.Calls(), Not(::testing::Contains(HasSubstr("-faults"))));
  EXPECT_THAT(api_.Calls(), Not(::testing::Contains(HasSubstr("exec "))));
  ExpectNothingLeft();
}

TEST_F(FaultRunnerTest, AnImuBiasStillActiveAtTheEndIsNotTakenBack) {
  spec_.Fault("{name: bias, at: 1s, duration: 60s, imu_bias: {target: scout_1, accel_m_s2: [0.3, 0, 0]}}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.500 node=physics event=clock",
                                   "t=3.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  const auto calls = api_.Calls();
  // The jump, and no negated one: the physics server stops with the trial.
  EXPECT_EQ(Matching(calls, "--send-command").size(), 1u) << ::testing::PrintToString(calls);
  EXPECT_LT(IndexOf(calls, "exec " + Name("physics") + " " + kSend + "scout_1 imu_bias_jump 0.3 0 0"), calls.size());
  const std::string events = Events(run);
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"bias\""));
  EXPECT_THAT(events, HasSubstr("\"note\":\"with the physics server\",\"requested_t_sim_s\":"));
  ExpectNothingLeft();
}

}  // namespace
}  // namespace swarmbox::runner
