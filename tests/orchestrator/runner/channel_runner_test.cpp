// A radio.model channel trial run against FakeDockerApi: the radio plan written into the trial
// folder and copied into the physics container, no mesh network and no sidecars, and the runner's
// reaction to the physics server's reports of faults at simulated times (event=drone_out: the
// container action; event=drone_back: its reverse; event=radio_fault: recorded), each recorded in
// events.jsonl with the simulated time it landed. And the netem warning at rtf != 1, result.json's
// "radio".
#include <gmock/gmock.h>
#include <gtest/gtest.h>

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

constexpr char kRun[] = "20261126-020000-c4a7";
std::string Name(const std::string& component) { return std::string("chan-") + kRun + "-" + component; }

std::size_t IndexOfExact(const std::vector<std::string>& calls, const std::string& call) {
  for (std::size_t i = 0; i < calls.size(); ++i) {
    if (calls[i] == call) return i;
  }
  return calls.size();
}

// The events.jsonl records of one fault, in order.
std::vector<yaml::Node> FaultRecords(const std::string& events, const std::string& fault) {
  std::vector<yaml::Node> out;
  std::istringstream in(events);
  for (std::string line; std::getline(in, line);) {
    auto j = yaml::Parse(line, "events.jsonl");
    if (!j) continue;
    const yaml::Node* type = j->Find("type");
    const yaml::Node* name = j->Find("fault");
    if (type != nullptr && type->scalar() == "fault" && name != nullptr && name->scalar() == fault)
      out.push_back(*j);
  }
  return out;
}

class ChannelRunnerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    root_ = fs::temp_directory_path() / ("swarmbox-channel-runner-" + test);
    fs::remove_all(root_);
    // A trials folder of its own: the shipped world and airframe, and a radio profile fixture (the
    // runner only copies it; the physics server reads it).
    const fs::path trials = root_ / "trials";
    const fs::path shipped = fs::path(SWARMBOX_SOURCE_DIR) / "trials";
    fs::create_directories(trials / "worlds");
    fs::create_directories(trials / "airframes");
    fs::create_directories(trials / "radios");
    fs::copy_file(shipped / "worlds" / "open_field.yaml", trials / "worlds" / "open_field.yaml");
    fs::copy_file(shipped / "airframes" / "x500.yaml", trials / "airframes" / "x500.yaml");
    std::ofstream(trials / "radios" / "bench_radio.yaml") << "name: bench_radio\nfrequency_mhz: 5180\n";
    spec_ = dsl::TrialSpec::Named("chan")
                .Seed(11)
                .World("worlds/open_field.yaml")
                .Drone("scout_1", "x500", {0, 0, 0})
                .Drone("scout_2", "x500", {3, 0, 0})
                .Mission({dsl::MissionKind::kPlan, "takeoff:5,hover:10,land", 40})
                .EndOn("event=done", dsl::Outcome::kSuccess)
                .Timeout(dsl::Duration::Seconds(60), dsl::Outcome::kTimeout, dsl::Duration::Seconds(600));
    spec_.radio.profile = "bench_radio";
    spec_.trials_dir = trials.string();
    options_.out_dir = (root_ / "runs").string();
    options_.run_id = kRun;
    options_.images = {"swarmbox/physics:test", "swarmbox/agent:test"};
    options_.host = "fake-host-channel-" + test;
    options_.poll = std::chrono::milliseconds(5);
    api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready"};
  }
  void TearDown() override { fs::remove_all(root_); }

  RunOutcome Run() {
    testing::FakeClock clock(1000, 0.001);
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

  fs::path root_;
  dsl::TrialSpec spec_;
  RunOptions options_;
  testing::FakeDockerApi api_;
};

// The leader killed at exactly its simulated time: the physics server took it out of the lockstep
// at t=30 (the plan's entry, raft_leader resolved by the server) and the runner kills its container.
TEST_F(ChannelRunnerTest, KillsTheContainerTheServerTookOutAtItsSimulatedTime) {
  spec_.Mesh("{delay_ms: 100, jitter_ms: 20, distribution: normal, loss: 0.05}");
  spec_.Fault("{name: kill_leader, at: 30s, kill: raft_leader}");
  api_.scripts["physics"].lines = {
      "t=0.000 node=physics event=ready",
      "t=30.000 node=physics event=raft_leader_resolved fault=kill_leader drone=scout_2",
      "t=30.000 node=physics event=drone_out drone=scout_2 fault=kill_leader mode=kill",
      "t=31.000 node=physics event=tick",
      // The ending line on the physics server's own stream, after the drone_out: the fake engine
      // feeds the containers' logs concurrently, so an ending line of another container could be
      // read before the drone_out (in a real trial it comes long after).
      "t=35.000 node=physics event=done"};
  api_.scripts["scout_1"].lines = {"t=1.0 node=scout_1 event=takeoff"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  ExpectNothingLeft();

  // No mesh network, no sidecars, no exec: the impairment is the channel's.
  const auto calls = api_.Calls();
  EXPECT_EQ(IndexOfExact(calls, "create-network " + Name("net2-mesh")), calls.size());
  for (const auto& c : api_.Created()) {
    EXPECT_THAT(c.name, Not(HasSubstr("-faults")));
    EXPECT_TRUE(c.cap_add.empty()) << c.name;
  }
  for (const std::string& c : calls) EXPECT_EQ(c.rfind("exec ", 0), std::string::npos) << c;
  const std::size_t kill = IndexOfExact(calls, "kill " + Name("scout_2") + " SIGKILL");
  ASSERT_LT(kill, calls.size());
  EXPECT_EQ(IndexOfExact(calls, "kill " + Name("scout_1") + " SIGKILL"), calls.size());

  // The plan in the trial folder, and in the physics container's volume.
  const std::string plan = ReadFile(fs::path(run.trial_dir) / "radio_plan.json");
  EXPECT_EQ(
      plan,
      R"({"seed":11,"mesh":{"delay_ms":100,"jitter_ms":20,"distribution":"normal","loss":0.05,"rate_kbit":0,)"
      R"("duplicate":0},"schedule":[{"at_s":30,"name":"kill_leader","kind":"drone_out","mode":"kill",)"
      R"("targets":["raft_leader"],"duration_s":0}]})"
      "\n");
  const std::string tar = api_.PutArchives().at(Name("physics"));
  EXPECT_THAT(tar, HasSubstr("radio_plan.json"));
  EXPECT_THAT(tar, HasSubstr(plan));
  EXPECT_THAT(tar, HasSubstr("trials/radios/bench_radio.yaml"));
  std::vector<std::string> physics_argv;
  for (const auto& c : api_.Created()) {
    if (c.name == Name("physics")) {
      physics_argv = c.entrypoint;
      physics_argv.insert(physics_argv.end(), c.cmd.begin(), c.cmd.end());
    }
  }
  EXPECT_THAT(physics_argv,
              ::testing::IsSupersetOf({std::string("--radio-plan"), std::string("/swarmbox/radio_plan.json"),
                                       std::string("/swarmbox/trials/radios/bench_radio.yaml")}));

  // events.jsonl: requested and applied at the simulated time it landed, on the resolved drone.
  const auto records = FaultRecords(Events(run), "kill_leader");
  ASSERT_GE(records.size(), 2u) << Events(run);
  EXPECT_EQ(records[0].Find("phase")->scalar(), "requested");
  EXPECT_EQ(records[0].Find("t_sim_s")->scalar(), "30");
  EXPECT_EQ(records[0].Find("targets")->items().at(0).scalar(), "scout_2");
  EXPECT_EQ(records[0].Find("mechanism")->scalar(), "docker");
  EXPECT_EQ(records[1].Find("phase")->scalar(), "applied");
  EXPECT_EQ(records[1].Find("t_sim_s")->scalar(), "30");
  EXPECT_EQ(records[1].Find("requested_t_sim_s")->scalar(), "30");
  EXPECT_EQ(records[1].Find("kind")->scalar(), "kill");

  // result.json: which radio ran.
  auto result = yaml::Parse(ReadFile(fs::path(run.trial_dir) / "result.json"), "result.json");
  ASSERT_TRUE(result) << result.error().ToString();
  EXPECT_EQ(result->Find("radio")->Find("model")->scalar(), "channel");
  EXPECT_EQ(result->Find("radio")->Find("profile")->scalar(), "bench_radio");
}

// A stop with a duration: docker stop when the drone leaves the lockstep, start when the server
// brings it back; its log is followed again.
TEST_F(ChannelRunnerTest, StopsAndStartsAgainWhenTheServerBringsTheDroneBack) {
  spec_.Fault("{name: halt, at: 10s, duration: 5s, stop: {target: scout_1, timeout: 3s}}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready",
                                   "t=10.000 node=physics event=drone_out drone=scout_1 fault=halt mode=stop",
                                   "t=15.000 node=physics event=drone_back drone=scout_1 fault=halt"};
  api_.scripts["scout_1"].lines = {"t=0.5 node=scout_1 event=takeoff"};
  api_.scripts["scout_1"].restart_lines = {"t=15.1 node=scout_1 event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_EQ(run.result.verdict.source, "scout_1");
  ExpectNothingLeft();
  const auto calls = api_.Calls();
  const std::size_t stop = IndexOfExact(calls, "stop " + Name("scout_1"));
  ASSERT_LT(stop, calls.size());
  std::size_t start_again = calls.size();
  for (std::size_t i = stop; i < calls.size(); ++i) {
    if (calls[i] == "start " + Name("scout_1")) start_again = std::min(start_again, i);
  }
  EXPECT_LT(start_again, calls.size());
  EXPECT_EQ(ReadFile(fs::path(run.trial_dir) / "logs" / "scout_1.log"),
            "t=0.5 node=scout_1 event=takeoff\nt=15.1 node=scout_1 event=done\n");

  const auto records = FaultRecords(Events(run), "halt");
  ASSERT_EQ(records.size(), 4u) << Events(run);
  EXPECT_EQ(records[0].Find("phase")->scalar(), "requested");
  EXPECT_EQ(records[1].Find("phase")->scalar(), "applied");
  EXPECT_EQ(records[1].Find("t_sim_s")->scalar(), "10");
  EXPECT_EQ(records[2].Find("phase")->scalar(), "remove_requested");
  EXPECT_EQ(records[2].Find("t_sim_s")->scalar(), "15");
  EXPECT_EQ(records[3].Find("phase")->scalar(), "removed");
  EXPECT_EQ(records[3].Find("t_sim_s")->scalar(), "15");
  EXPECT_EQ(records[3].Find("requested_t_sim_s")->scalar(), "15");
}

// A pause and its end (unpause); a kill with the fault's own signal; a radio fault the channel
// carried out, recorded as the server reports it.
TEST_F(ChannelRunnerTest, PausesKillsWithTheFaultsSignalAndRecordsTheChannelsRadioFaults) {
  spec_.Fault("{name: nap, at: 5s, duration: 2s, pause: scout_1}");
  spec_.Fault("{name: term, at: 8s, kill: {target: scout_2, signal: SIGTERM}}");
  spec_.Fault("{name: fade, at: 6s, duration: 1s, radio: {target: scout_1, loss: 0.3}}");
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready",
                                   "t=5.000 node=physics event=drone_out drone=scout_1 fault=nap mode=pause",
                                   "t=6.000 node=physics event=radio_fault fault=fade kind=impair state=on",
                                   "t=7.000 node=physics event=radio_fault fault=fade kind=impair state=off",
                                   "t=7.000 node=physics event=drone_back drone=scout_1 fault=nap",
                                   "t=8.000 node=physics event=drone_out drone=scout_2 fault=term mode=kill",
                                   "t=9.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  ExpectNothingLeft();
  const auto calls = api_.Calls();
  const std::size_t pause = IndexOfExact(calls, "pause " + Name("scout_1"));
  const std::size_t unpause = IndexOfExact(calls, "unpause " + Name("scout_1"));
  ASSERT_LT(pause, calls.size());
  ASSERT_LT(unpause, calls.size());
  EXPECT_LT(pause, unpause);
  EXPECT_LT(unpause, IndexOfExact(calls, "kill " + Name("scout_2") + " SIGTERM"));
  EXPECT_LT(IndexOfExact(calls, "kill " + Name("scout_2") + " SIGTERM"), calls.size());

  const auto fade = FaultRecords(Events(run), "fade");
  ASSERT_EQ(fade.size(), 2u) << Events(run);
  EXPECT_EQ(fade[0].Find("phase")->scalar(), "applied");
  EXPECT_EQ(fade[0].Find("t_sim_s")->scalar(), "6");
  EXPECT_EQ(fade[0].Find("mechanism")->scalar(), "channel");
  EXPECT_EQ(fade[1].Find("phase")->scalar(), "removed");
  EXPECT_EQ(fade[1].Find("t_sim_s")->scalar(), "7");
  // The killed drone stays down to the end: recorded removed with the trial's end, not started.
  const auto term = FaultRecords(Events(run), "term");
  ASSERT_EQ(term.size(), 4u) << Events(run);
  EXPECT_EQ(term[3].Find("phase")->scalar(), "removed");
  EXPECT_THAT(term[3].Find("note")->scalar(), HasSubstr("left down"));
  std::size_t starts = 0;
  for (const std::string& c : calls) starts += c == "start " + Name("scout_2") ? 1u : 0u;
  EXPECT_EQ(starts, 1u);
}

// A kill that ends (leader_kill_failover.yaml's): the server keeps the drone out as its `restart`
// for the duration; the container is killed with the fault's signal and started when it is back.
// A raft_leader the server could not resolve is recorded failed.
TEST_F(ChannelRunnerTest, AKillWithADurationKillsThenStartsAndASkippedFaultIsRecordedFailed) {
  spec_.Fault("{name: kill_leader_1, at: 15s, duration: 10s, kill: raft_leader}");
  spec_.Fault("{name: kill_leader_2, at: 30s, kill: raft_leader}");
  api_.scripts["physics"].lines = {
      "t=0.000 node=physics event=ready",
      "t=15.000 node=physics event=raft_leader_resolved fault=kill_leader_1 drone=scout_1",
      "t=15.000 node=physics event=drone_out drone=scout_1 fault=kill_leader_1 mode=restart",
      "t=25.000 node=physics event=drone_back drone=scout_1 fault=kill_leader_1",
      "t=30.000 node=physics event=fault_skipped fault=kill_leader_2 reason=\"no drone leads the Raft "
      "group\""};
  api_.scripts["scout_1"].restart_lines = {"t=25.5 node=scout_1 event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_EQ(run.result.verdict.source, "scout_1");
  const auto calls = api_.Calls();
  const std::size_t kill = IndexOfExact(calls, "kill " + Name("scout_1") + " SIGKILL");
  ASSERT_LT(kill, calls.size());
  bool started_after = false;
  for (std::size_t i = kill; i < calls.size(); ++i)
    started_after = started_after || calls[i] == "start " + Name("scout_1");
  EXPECT_TRUE(started_after);
  EXPECT_EQ(IndexOfExact(calls, "stop " + Name("scout_1")) < kill, false);
  const auto skipped = FaultRecords(Events(run), "kill_leader_2");
  ASSERT_EQ(skipped.size(), 1u) << Events(run);
  EXPECT_EQ(skipped[0].Find("phase")->scalar(), "failed");
  EXPECT_EQ(skipped[0].Find("t_sim_s")->scalar(), "30");
  EXPECT_THAT(skipped[0].Find("error")->scalar(), HasSubstr("no drone leads the Raft group"));
  ExpectNothingLeft();
}

// A drone the server pauses and never brings back is unpaused at the end, so it can stop.
TEST_F(ChannelRunnerTest, ADroneStillPausedAtTheEndIsUnpausedBeforeTheContainersStop) {
  spec_.Fault("{name: freeze, at: 1s, pause: scout_2}");
  api_.scripts["physics"].lines = {
      "t=0.000 node=physics event=ready",
      "t=1.000 node=physics event=drone_out drone=scout_2 fault=freeze mode=pause",
      "t=2.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  const auto calls = api_.Calls();
  const std::size_t unpause = IndexOfExact(calls, "unpause " + Name("scout_2"));
  ASSERT_LT(unpause, calls.size());
  EXPECT_LT(IndexOfExact(calls, "pause " + Name("scout_2")), unpause);
  EXPECT_LT(unpause, IndexOfExact(calls, "stop " + Name("scout_2")));
  ExpectNothingLeft();
}

// A report that matches no entry of the plan means the two disagree: the trial ends with error.
TEST_F(ChannelRunnerTest, AReportOfAFaultNotInThePlanEndsTheTrialWithError) {
  spec_.Fault("{name: kill_leader, at: 30s, kill: raft_leader}");
  api_.scripts["physics"].lines = {
      "t=0.000 node=physics event=ready",
      "t=30.000 node=physics event=drone_out drone=scout_1 fault=other mode=kill",
      "t=31.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kError);
  EXPECT_THAT(run.result.verdict.reason, HasSubstr("fault 'other', which is not in the radio plan"));
  EXPECT_EQ(IndexOfExact(api_.Calls(), "kill " + Name("scout_1") + " SIGKILL"), api_.Calls().size());
  ExpectNothingLeft();
}

// Faults on log events stay with the runner in channel trials too.
TEST_F(ChannelRunnerTest, FaultsOnLogEventsAreStillTheRunners) {
  spec_.Fault("{name: kill_leader, on: \"event=leader_elected\", duration: 200ms, kill: raft_leader}");
  api_.scripts["scout_1"].lines = {"t=1.0 node=scout_1 event=leader_elected term=2 leader=scout_2"};
  api_.scripts["scout_2"].restart_lines = {"t=4.1 node=scout_2 event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_LT(IndexOfExact(api_.Calls(), "kill " + Name("scout_2") + " SIGKILL"), api_.Calls().size());
  EXPECT_EQ(ReadFile(fs::path(run.trial_dir) / "radio_plan.json"), "{\"seed\":11,\"schedule\":[]}\n");
  ExpectNothingLeft();
}

// netem at rtf 0: its radio runs on the wall clock; the run says so in events.jsonl.
TEST_F(ChannelRunnerTest, NetemAtAnotherRtfThanOneIsWarnedAbout) {
  spec_.radio.model = dsl::RadioModel::kNetem;
  spec_.Rtf(0);
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.000 node=physics event=done"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  const std::string events = Events(run);
  EXPECT_THAT(
      events,
      HasSubstr("\"component\":\"orchestrator\",\"event\":\"warning\",\"reason\":\"radio.model netem runs "
                "the radio on the wall clock: at rtf 0"));
  EXPECT_FALSE(fs::exists(fs::path(run.trial_dir) / "radio_plan.json"));
  auto result = yaml::Parse(ReadFile(fs::path(run.trial_dir) / "result.json"), "result.json");
  ASSERT_TRUE(result);
  EXPECT_EQ(result->Find("radio")->Find("model")->scalar(), "netem");
  EXPECT_TRUE(result->Find("radio")->Find("profile")->is_null() ||
              yaml::IsNullScalar(*result->Find("radio")->Find("profile")));
  EXPECT_EQ(RadioRtfWarning("netem", 1.0), std::nullopt);
  EXPECT_EQ(RadioRtfWarning("channel", 0.0), std::nullopt);
  EXPECT_NE(RadioRtfWarning("netem", 2.0), std::nullopt);
  ExpectNothingLeft();
}

// The default profile must exist before anything is created.
TEST_F(ChannelRunnerTest, AMissingRadioProfileStopsBeforeAnythingIsCreated) {
  spec_.radio.profile = "no_such_radio";
  testing::FakeClock clock(1000, 0.001);
  auto run = RunTrialSpec(spec_, api_, clock, options_);
  ASSERT_FALSE(run);
  EXPECT_THAT(run.error().message(), HasSubstr("radio profile 'no_such_radio' not found"));
  EXPECT_TRUE(api_.Calls().empty());
}

}  // namespace
}  // namespace swarmbox::runner
