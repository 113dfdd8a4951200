// MissionHost (agent/app/mission_host.hpp) without any bus: the mode strings on DroneState, what
// the agent reads from the airframe, and how the host turns the behaviours into flight setpoints,
// leader proposals and the lifter's load check, stepped by hand on simulated time.
#include "mission_host.hpp"

#include <gtest/gtest.h>

#include <string>
#include <variant>
#include <vector>

namespace swarmbox::agent {
namespace {

using flight::FlightMode;
using flight::Setpoint;
using flight::Vec3;

bool HasEvent(const MissionHostOutput& out, const std::string& name) {
  for (const LogEvent& e : out.events) {
    if (e.str().find(" event=" + name) != std::string::npos) return true;
  }
  return false;
}

TEST(MissionMode, RoundTripsRoleAndModeAndRejectsOthers) {
  EXPECT_EQ(EncodeMissionMode(swarm::Role::kScout, "searching"), "scout/searching");
  swarm::Role role = swarm::Role::kScout;
  std::string mode;
  ASSERT_TRUE(DecodeMissionMode("lifter/standby", &role, &mode));
  EXPECT_EQ(role, swarm::Role::kLifter);
  EXPECT_EQ(mode, "standby");
  for (const char* bad : {"hold", "pilot/x", "scout/", "/x", ""}) {
    EXPECT_FALSE(DecodeMissionMode(bad, &role, &mode)) << bad;
  }
}

TEST(AirframeExtras, ReadsTheCameraAndWhereTheStretcherLies) {
  auto cam = LoadCameraSpec(SWARMBOX_TRIALS_DIR "/airframes/x500.yaml");
  ASSERT_TRUE(cam.ok()) << cam.error().ToString();
  EXPECT_EQ(cam->width_px, 320);
  EXPECT_EQ(cam->height_px, 240);
  EXPECT_DOUBLE_EQ(cam->hfov_rad, 1.2);
  EXPECT_EQ(cam->offset_m, Vec3(0, 0, -0.05));
  // x8_heavy: collision box 4.4 m wide, stretcher 0.6 m wide -> 2.2 + 0.3 + 0.5 = 3 m to the south.
  auto g = LoadGroundPayload(SWARMBOX_TRIALS_DIR "/airframes/x8_heavy.yaml", "stretcher");
  ASSERT_TRUE(g.ok()) << g.error().ToString();
  EXPECT_NEAR(g->offset_m.x(), 0.0, 1e-12);
  EXPECT_NEAR(g->offset_m.y(), -3.0, 1e-12);
  EXPECT_NEAR(g->half_height_m, 0.125, 1e-12);
  auto none = LoadGroundPayload(SWARMBOX_TRIALS_DIR "/airframes/x500.yaml", "stretcher");
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().ToString().find("no payload 'stretcher'"), std::string::npos) << none.error().ToString();
}

MissionHostConfig Scout(const std::string& name, std::vector<std::string> members) {
  MissionHostConfig c;
  c.name = name;
  c.members = std::move(members);
  c.airframe = "x500";
  c.has_home = true;
  c.home_m = Vec3(0, 0, 0);
  return c;
}

TEST(MissionHostCreate, RejectsBadConfigurations) {
  MissionHostConfig c = Scout("scout_9", {"scout_1"});
  auto r = MissionHost::Create(c);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().ToString().find("does not include 'scout_9'"), std::string::npos);
  c = Scout("scout_1", {"scout_1"});
  c.airframe = "glider";
  r = MissionHost::Create(c);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().ToString().find("battery"), std::string::npos) << r.error().ToString();
  c = Scout("scout_1", {"scout_1"});
  c.geofence_size_x_m = 10.0;
  r = MissionHost::Create(c);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().ToString().find("too small"), std::string::npos);
}

// A host stepped at the lockstep rate with an estimate the test moves by hand.
class HostRig {
 public:
  explicit HostRig(const MissionHostConfig& c) : host_(*MissionHost::Create(c)) { est_.valid = true; }
  const MissionHostOutput& Step(FlightMode mode, bool leader = false, bool hover = false, double mass_kg = 0) {
    t_ += 0.004;
    wall_ += 0.004 / speed_up_;
    est_.t_s = t_;
    host_->RecordEstimate(t_, est_);
    MissionHostInput in;
    in.t_s = t_;
    if (speed_up_ > 0) in.wall_s = wall_;
    in.flight_mode = mode;
    in.estimate = &est_;
    in.mission = &mission_;
    in.is_leader = leader;
    in.hover_event = hover;
    in.mass_estimate_kg = mass_kg;
    return host_->Step(in);
  }
  // Steps `seconds` and returns every setpoint commanded meanwhile.
  std::vector<Setpoint> Run(double seconds, FlightMode mode, bool leader = false) {
    std::vector<Setpoint> sent;
    for (double end = t_ + seconds; t_ < end;) {
      const MissionHostOutput& out = Step(mode, leader);
      if (out.command) sent.push_back(*out.command);
      for (const raft::MissionCommand& c : out.proposals) proposals_.push_back(c);
    }
    return sent;
  }
  // Passes wall times from now on: the world runs `speed_up` times faster than the wall clock
  // (1: rtf 1; ~8 at rtf 0 on loopback). Without it the host gets no wall clock (NaN).
  void PassWallTime(double speed_up) { speed_up_ = speed_up; }
  double wall_s() const { return wall_; }
  MissionHost& host() { return *host_; }
  flight::StateEstimate& estimate() { return est_; }
  raft::MissionState& mission() { return mission_; }
  std::vector<raft::MissionCommand>& proposals() { return proposals_; }

 private:
  std::unique_ptr<MissionHost> host_;
  flight::StateEstimate est_;
  raft::MissionState mission_;
  std::vector<raft::MissionCommand> proposals_;
  double t_ = 0.0;
  double wall_ = 100.0;  // any monotonic origin
  double speed_up_ = -1.0;  // <= 0: no wall clock
};

TEST(MissionHostScout, TakesOffShortThenClimbsInPositionModeAndPublishesItsMode) {
  HostRig rig(Scout("scout_1", {"scout_1"}));
  rig.estimate().pos_m = Vec3(0, 0, 0.23);
  const MissionHostOutput& first = rig.Step(FlightMode::kIdle);
  EXPECT_TRUE(HasEvent(first, "mission_start"));
  EXPECT_EQ(rig.host().mode(), "scout/on_ground");
  std::vector<Setpoint> sent = rig.Run(1.5, FlightMode::kIdle);
  EXPECT_TRUE(sent.empty());  // 2 s on the ground first (the estimator settles)
  sent = rig.Run(1.0, FlightMode::kIdle);  // (re-sent each tick while the drone stays idle)
  ASSERT_FALSE(sent.empty());
  for (const Setpoint& sp : sent) {
    EXPECT_EQ(sp.kind, Setpoint::Kind::kTakeoff);
    EXPECT_DOUBLE_EQ(sp.value.z(), 3.0);  // the short flight-stack take-off
  }
  EXPECT_EQ(rig.host().mode(), "scout/taking_off");
  rig.estimate().pos_m = Vec3(0, 0, 3.2);
  sent = rig.Run(1.0, FlightMode::kTakeoff);
  EXPECT_TRUE(sent.empty());
  sent = rig.Run(0.5, FlightMode::kHold);  // take-off height reached: the flight stack holds
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_EQ(sent[0].kind, Setpoint::Kind::kPosition);
  EXPECT_EQ(sent[0].value, Vec3(0, 0, 30));  // then the climb to the search altitude
}

TEST(MissionHostScout, AloneAndLeadingItAssignsItselfTheWholeSearchAreaAndStarts) {
  HostRig rig(Scout("scout_1", {"scout_1"}));
  rig.estimate().pos_m = Vec3(0, 0, 0.23);
  rig.Run(2.5, FlightMode::kIdle, /*leader=*/true);
  EXPECT_TRUE(rig.proposals().empty());  // on the ground: no search yet
  rig.estimate().pos_m = Vec3(0, 0, 29.5);
  rig.Run(0.5, FlightMode::kPosition, true);
  ASSERT_EQ(rig.proposals().size(), 2u);
  const auto* assign = std::get_if<raft::AssignSectors>(&rig.proposals()[0]);
  ASSERT_NE(assign, nullptr);
  ASSERT_EQ(assign->sectors.size(), 1u);
  // The 200 x 200 m geofence shrunk by the search margin (8 m).
  EXPECT_DOUBLE_EQ(assign->sectors[0].x_min_m, -92.0);
  EXPECT_DOUBLE_EQ(assign->sectors[0].y_max_m, 92.0);
  EXPECT_TRUE(std::holds_alternative<raft::StartSearch>(rig.proposals()[1]));
  // Committed: it flocks along its first lane (a velocity setpoint every mission tick).
  rig.mission().Apply(1, rig.proposals()[0]);
  rig.mission().Apply(2, rig.proposals()[1]);
  rig.estimate().pos_m = Vec3(0, 0, 30);
  const std::vector<Setpoint> sent = rig.Run(1.0, FlightMode::kVelocity, true);
  ASSERT_GE(sent.size(), 9u);
  EXPECT_EQ(sent.back().kind, Setpoint::Kind::kVelocity);
  EXPECT_EQ(rig.host().mode(), "scout/searching");
}

TEST(MissionHostScout, WaitsForEveryMemberBeforeStartingAndReadsTheirRoles) {
  HostRig rig(Scout("scout_1", {"scout_1", "lifter"}));
  rig.estimate().pos_m = Vec3(0, 0, 0.23);
  rig.Run(3.0, FlightMode::kIdle);
  EXPECT_EQ(rig.host().mode(), "scout/on_ground");  // not started: the lifter is unheard
  PeerState lifter;
  lifter.name = "lifter";
  lifter.mode = "lifter/on_ground";
  lifter.sim_time_s = 3.0;
  rig.host().OnPeerState(lifter);
  const MissionHostOutput& out = rig.Step(FlightMode::kIdle);
  ASSERT_TRUE(HasEvent(out, "mission_start"));
  EXPECT_NE(out.events.front().str().find("lifter_present=true"), std::string::npos) << out.events.front().str();
}

// The leader's roster ages each peer on the simulated clock: a scout whose DroneState stops is
// gone after member_timeout_s (6 s) and its committed sector is handed over through Raft.
TEST(MissionHostScout, LeadingItHandsASilentPeersSectorOverAfterTheMemberTimeout) {
  HostRig rig(Scout("scout_1", {"scout_1", "scout_2"}));
  rig.mission().Apply(1, raft::AssignSectors{{{"scout_1", -92, -92, 0, 92}, {"scout_2", 0, -92, 92, 92}}});
  rig.mission().Apply(2, raft::StartSearch{});
  rig.estimate().pos_m = Vec3(0, 0, 30);
  PeerState peer;
  peer.name = "scout_2";
  peer.mode = "scout/searching";
  peer.position_m = Vec3(50, 0, 30);
  const auto handed_over = [&] {
    for (const raft::MissionCommand& c : rig.proposals()) {
      if (std::holds_alternative<raft::AssignSectors>(c)) return true;
    }
    return false;
  };
  for (double t = 0.0; t < 10.0; t += 0.5) {  // heard at 5 Hz (every other half second here)
    peer.sim_time_s = t;
    rig.host().OnPeerState(peer);
    rig.Run(0.5, FlightMode::kVelocity, /*leader=*/true);
  }
  EXPECT_FALSE(handed_over());
  rig.Run(5.0, FlightMode::kVelocity, true);  // last state taken at 9.5 s: 5.5 s of silence
  EXPECT_FALSE(handed_over());
  rig.Run(1.5, FlightMode::kVelocity, true);
  ASSERT_TRUE(handed_over());
  for (const raft::MissionCommand& c : rig.proposals()) {
    const auto* a = std::get_if<raft::AssignSectors>(&c);
    if (a == nullptr) continue;
    for (const raft::Sector& sector : a->sectors) EXPECT_EQ(sector.drone, "scout_1");
    EXPECT_EQ(a->sectors.size(), 2u);
  }
}

// With wall times (the node stamps each DroneState when it takes it off the bus): at rtf 0 the
// world runs ~10x faster than the radio delivers, so 6 s of simulated silence is 0.6 s of wall
// time, a delayed sample, not a lost drone; the sector goes over once the peer is also 3 s silent
// on the wall clock. At rtf 1 the 6 s simulated timeout decides, as without wall times.
TEST(MissionHostScout, AtRtf0APeerIsLostOnlyWhenAlsoSilentOnTheWallClock) {
  for (const double speed_up : {10.0, 1.0}) {
    SCOPED_TRACE("speed-up " + std::to_string(speed_up));
    HostRig rig(Scout("scout_1", {"scout_1", "scout_2"}));
    rig.PassWallTime(speed_up);
    rig.mission().Apply(1, raft::AssignSectors{{{"scout_1", -92, -92, 0, 92}, {"scout_2", 0, -92, 92, 92}}});
    rig.mission().Apply(2, raft::StartSearch{});
    rig.estimate().pos_m = Vec3(0, 0, 30);
    PeerState peer;
    peer.name = "scout_2";
    peer.mode = "scout/searching";
    peer.position_m = Vec3(50, 0, 30);
    const auto handed_over = [&] {
      for (const raft::MissionCommand& c : rig.proposals()) {
        if (std::holds_alternative<raft::AssignSectors>(c)) return true;
      }
      return false;
    };
    for (double t = 0.0; t < 10.0; t += 0.5) {
      peer.sim_time_s = t;
      peer.received_wall_s = rig.wall_s();
      rig.host().OnPeerState(peer);
      rig.Run(0.5, FlightMode::kVelocity, /*leader=*/true);
    }
    rig.Run(5.0, FlightMode::kVelocity, true);  // last state taken at 9.5 s: 5.5 s of silence
    EXPECT_FALSE(handed_over());
    rig.Run(1.5, FlightMode::kVelocity, true);  // 7 s simulated: 7 s wall at rtf 1, 0.7 s at 10x
    if (speed_up == 1.0) {
      EXPECT_TRUE(handed_over());
      continue;
    }
    EXPECT_FALSE(handed_over());
    rig.Run(21.0, FlightMode::kVelocity, true);  // 28 s simulated, 2.8 s wall
    EXPECT_FALSE(handed_over());
    rig.Run(3.0, FlightMode::kVelocity, true);   // 31 s simulated, 3.1 s wall
    EXPECT_TRUE(handed_over());
  }
}

TEST(MissionHostLifter, TheLoadCheckDropsAnAttachTheWorldDidNotCarryOut) {
  MissionHostConfig c;
  c.name = "lifter";
  c.members = {"lifter"};
  c.airframe = "x8_heavy";
  c.payload = "stretcher";
  c.base_height_m = 0.6;
  c.vehicle_mass_kg = 120.0;
  c.has_home = true;
  c.payload_offset_m = Eigen::Vector2d(0, -3);
  HostRig rig(c);
  // A rescue for this lifter is committed.
  raft::MissionState& m = rig.mission();
  std::uint64_t i = 0;
  ASSERT_TRUE(m.Apply(++i, raft::AssignSectors{{{"scout_1", -50, -50, 50, 50}}}).accepted);
  ASSERT_TRUE(m.Apply(++i, raft::StartSearch{}).accepted);
  ASSERT_TRUE(m.Apply(++i, raft::ConfirmVictim{"operator", 40, 0}).accepted);
  ASSERT_TRUE(m.Apply(++i, raft::ConvergeOn{1}).accepted);
  ASSERT_TRUE(m.Apply(++i, raft::BeginRescue{1, "lifter"}).accepted);
  rig.estimate().pos_m = Vec3(0, 0, 0.6);
  rig.Run(0.2, FlightMode::kIdle);
  EXPECT_EQ(rig.host().mode(), "lifter/takeoff_for_pickup");
  // Hover settled over the stretcher at the hook height: the attach goes out as a world command.
  rig.estimate().pos_m = Vec3(0, -3, 4.525);
  bool attach = false;
  for (int k = 0; k < 1000 && !attach; ++k) {
    const MissionHostOutput& out = rig.Step(FlightMode::kPosition);
    attach = out.payload.action == swarm::PayloadAction::kAttach;
    if (attach) {
      EXPECT_DOUBLE_EQ(out.payload.mass_kg, 15.0);
    }
  }
  ASSERT_TRUE(attach);
  EXPECT_TRUE(rig.host().payload_attached());
  // Climbing 4 m higher, 5 s later, the flight stack still feels only the empty airframe.
  rig.estimate().pos_m = Vec3(0, -3, 8.6);
  bool missing = false;
  for (int k = 0; k < 2000 && !missing; ++k) missing = HasEvent(rig.Step(FlightMode::kPosition, false, false, 120.5), "payload_missing");
  ASSERT_TRUE(missing);
  EXPECT_FALSE(rig.host().payload_attached());
  rig.Run(0.3, FlightMode::kPosition);
  EXPECT_EQ(rig.host().mode(), "lifter/takeoff_for_pickup");  // back over the stretcher
}

}  // namespace
}  // namespace swarmbox::agent
