// Sensor faults with the real programs on the real engine: a short kind plan trial (physics server
// + one agent: take-off, a 20 s hover, land) with `{at: 8s, duration: 3s, gps_dropout: scout_1}` and then
// `{at: 12s, duration: 2s, gps_degrade: {target: scout_1, h_acc_m: 5, v_acc_m: 8}}`. The runner
// execs `swarmbox-physics --send-command scout_1 gps_dropout 3` (and `... gps_degrade 2 5 8`) in
// the physics container; events.jsonl records each apply and removal with mechanism
// physics-command, the physics log shows the server took both commands, and nothing labelled
// remains.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

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

TEST(SensorFaultE2e, GpsDropoutAndDegradationAreSentToThePhysicsServerAndRecorded) {
  swarmbox::testing::TrialOnDocker engine;
  const Status ready = engine.Prepare("sensor-fault-e2e", {SWARMBOX_PHYSICS_BIN, SWARMBOX_AGENT_BIN, ""});
  ASSERT_TRUE(ready) << ready.error().ToString();
  docker::DockerApi& api = engine.api();

  dsl::TrialSpec spec = dsl::TrialSpec::Named("sensor-fault-e2e")
                            .Seed(5)
                            .World("worlds/open_field.yaml")
                            .Rtf(1.0)
                            .Drone("scout_1", "x500", {0, 0, 0})
                            // Hover 20 s: the faults (8-11 s, 12-14 s, each applied an exec's
                            // latency late: seconds on a loaded CI host) end well before the landing.
                            // With hover 10 the landing began ~1 s after the degraded fix was due to
                            // end, and a CI run's late commands had the drone land on a 5 m / 8 m fix:
                            // event=crash.
                            .Mission({dsl::MissionKind::kPlan, "takeoff:3,hover:20,land", 40})
                            .EndOn("event=plan_complete", dsl::Outcome::kSuccess, {}, "scout_1")
                            .EndOn("event=crash", dsl::Outcome::kFailure, "crash")
                            .Timeout(dsl::Duration::Seconds(60), dsl::Outcome::kTimeout, dsl::Duration::Seconds(240));
  spec.Fault("{name: gps_loss, at: 8s, duration: 3s, gps_dropout: scout_1}");
  spec.Fault("{name: bad_fix, at: 12s, duration: 2s, gps_degrade: {target: scout_1, h_acc_m: 5, v_acc_m: 8}}");
  spec.trials_dir = std::string(SWARMBOX_SOURCE_DIR) + "/trials";
  spec.radio.model = dsl::RadioModel::kNetem;  // sent by `--send-command` (the channel's plan has them)

  const fs::path out = engine.options().out_dir;
  const RunOptions& options = engine.options();
  const docker::LabelSelector& mine = engine.mine();

  SteadyClock clock;
  Result<RunOutcome> run = RunTrialSpec(spec, api, clock, options);
  ASSERT_TRUE(run) << run.error().ToString();
  // Not an error: the fault was carried out (a dropout of 3 s in a hover is flown through).
  EXPECT_EQ(run->result.verdict.outcome, dsl::Outcome::kSuccess) << run->result.verdict.ToString();

  const std::string events = ReadFile(fs::path(run->trial_dir) / "events.jsonl");
  // Requested when due, applied once the world command's exec exited 0, with the request's times.
  const std::size_t requested = events.find("\"phase\":\"requested\",\"fault\":\"gps_loss\",\"kind\":\"gps_dropout\"");
  const std::size_t applied = events.find("\"phase\":\"applied\",\"fault\":\"gps_loss\",\"kind\":\"gps_dropout\"");
  ASSERT_NE(requested, std::string::npos) << events;
  ASSERT_NE(applied, std::string::npos) << events;
  EXPECT_LT(requested, applied);
  EXPECT_NE(events.find("\"requested_wall_s\":", applied), std::string::npos);
  EXPECT_THAT(events, HasSubstr("\"phase\":\"remove_requested\",\"fault\":\"gps_loss\""));
  EXPECT_THAT(events, HasSubstr("\"targets\":[\"scout_1\"],\"mechanism\":\"physics-command\""));
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"gps_loss\""));
  EXPECT_THAT(events, HasSubstr("\"phase\":\"applied\",\"fault\":\"bad_fix\",\"kind\":\"gps_degrade\""));
  EXPECT_THAT(events, HasSubstr("\"phase\":\"removed\",\"fault\":\"bad_fix\""));
  EXPECT_THAT(events, Not(HasSubstr("\"phase\":\"failed\"")));
  const std::string physics_log = ReadFile(fs::path(run->trial_dir) / "logs" / "physics.log");
  EXPECT_THAT(physics_log, HasSubstr("event=world_command command=gps_dropout target=scout_1")) << physics_log;
  EXPECT_THAT(physics_log, HasSubstr("event=world_command command=gps_degrade target=scout_1")) << physics_log;

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
