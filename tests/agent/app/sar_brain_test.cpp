// SarBrain (agent/app/sar_brain.hpp) through the brain SDK only, without any bus: the mode
// strings on DroneState, what the brain reads from the airframe and its Context, and how it turns
// the behaviours into commands and TrajectorySetpoint-form setpoints, leader proposals (encoded
// MissionCommands) and the lifter's load check, stepped by hand on simulated time with its own
// ReplicatedState as the committed mission.
#include "sar_brain.hpp"

#include <gtest/gtest.h>

#include "brain_host.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include "swarmbox/raft/mission_command.hpp"

namespace swarmbox::agent {
namespace {

using flight::Vec3;

bool HasEvent(const brain::Output& out, const std::string& name) {
  for (const brain::Event& e : out.events) {
    if (e.name == name) return true;
  }
  return false;
}

std::string Field(const brain::Event& e, const std::string& key) {
  for (const auto& [k, v] : e.fields) {
    if (k == key) return v;
  }
  return "";
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
  // The one airframe model (airframe/) the agent's brain, perception and flight stack share.
  auto x500 = airframe::LoadAirframe(SWARMBOX_TRIALS_DIR "/airframes/x500.yaml");
  ASSERT_TRUE(x500.ok()) << x500.error().ToString();
  ASSERT_TRUE(x500->has_camera);
  const airframe::CameraSpec* cam = &x500->camera;
  // The OAK-D Lite RGB of PX4's x500_depth, scaled 3:1 (trials/airframes/x500.yaml).
  EXPECT_EQ(cam->width_px, 640);
  EXPECT_EQ(cam->height_px, 360);
  EXPECT_DOUBLE_EQ(cam->hfov_rad, 1.204);
  EXPECT_EQ(cam->offset_m, (airframe::Vec3{0, 0, -0.05}));
  // x8_heavy: collision box 4.4 m wide, stretcher 0.6 m wide -> 2.2 + 0.3 + 0.5 = 3 m to the south.
  auto x8 = airframe::LoadAirframe(SWARMBOX_TRIALS_DIR "/airframes/x8_heavy.yaml");
  ASSERT_TRUE(x8.ok()) << x8.error().ToString();
  auto stretcher = x8->FindPayload("stretcher");
  ASSERT_TRUE(stretcher.ok()) << stretcher.error().ToString();
  const airframe::GroundPlacement g = airframe::PayloadOnGround(*x8, **stretcher);
  EXPECT_NEAR(g.offset_x_m, 0.0, 1e-12);
  EXPECT_NEAR(g.offset_y_m, -3.0, 1e-12);
  EXPECT_NEAR(g.half_height_m, 0.125, 1e-12);
  auto none = x500->FindPayload("stretcher");
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().ToString().find("no payload 'stretcher'"), std::string::npos) << none.error().ToString();
}

// What the agent hands the builtin brain: the files, the payload, args start and tuning.
brain::Context LifterContext() {
  brain::Context ctx;
  ctx.self = "lifter";
  ctx.members = {"scout_1", "lifter"};
  ctx.airframe = "x8_heavy";
  ctx.airframe_path = SWARMBOX_TRIALS_DIR "/airframes/x8_heavy.yaml";
  ctx.world_path = SWARMBOX_TRIALS_DIR "/worlds/open_field.yaml";
  ctx.payload = "stretcher";
  ctx.args = {{"start", "0,-10,0"}, {"member_timeout_s", "8"}};
  return ctx;
}

TEST(SarBrainConfigFrom, ReadsTheAirframeWorldPayloadStartAndTuningFromTheContext) {
  auto c = SarBrainConfigFrom(LifterContext());
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  EXPECT_EQ(c->name, "lifter");
  EXPECT_EQ(c->airframe, "x8_heavy");
  EXPECT_EQ(c->payload, "stretcher");
  EXPECT_TRUE(c->has_home);
  EXPECT_EQ(c->home_m, Vec3(0, -10, 0));
  EXPECT_NEAR(c->payload_offset_m.y(), -3.0, 1e-12);
  EXPECT_NEAR(c->payload_half_height_m, 0.125, 1e-12);
  EXPECT_GT(c->payload_sling_length_m, 0.0);
  EXPECT_GT(c->vehicle_mass_kg, 0.0);
  EXPECT_DOUBLE_EQ(c->tuning.member_timeout_s, 8.0);
  EXPECT_DOUBLE_EQ(c->tuning.member_min_wall_s, 3.0);  // untouched
  EXPECT_DOUBLE_EQ(c->period_s, 0.004);
}

// The sightings' fusion parameters are args too; values that would let one view confirm (or a
// miss not count) are refused at start-up with the reason.
TEST(SarBrainConfigFrom, ReadsTheFusionArgsAndRefusesOnesWhereOneViewWouldConfirm) {
  brain::Context ctx = LifterContext();
  ctx.args["fusion_min_baseline_m"] = "12";
  ctx.args["fusion_confirm_views"] = "3";
  ctx.args["revisit_look_s"] = "3";
  auto c = SarBrainConfigFrom(ctx);
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  EXPECT_DOUBLE_EQ(c->tuning.fusion.min_baseline_m, 12.0);
  EXPECT_EQ(c->tuning.fusion.confirm_views, 3);
  EXPECT_DOUBLE_EQ(c->tuning.revisit_look_s, 3.0);
  EXPECT_DOUBLE_EQ(c->tuning.fusion.prior, 0.5);  // untouched
  ctx.args["fusion_confirm_views"] = "1";
  c = SarBrainConfigFrom(ctx);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().ToString().find("confirm_views must be >= 2: a single view never confirms"), std::string::npos)
      << c.error().ToString();
}

// The close look: on by default (18 m, counted as close up to 21 m); a look altitude the fusion
// would not count as a close look is refused; 0 turns it off with fusion_close_look_height_m 0.
TEST(SarBrainConfigFrom, TheCloseLookMustCountAsOne) {
  brain::Context ctx = LifterContext();
  auto c = SarBrainConfigFrom(ctx);
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  EXPECT_DOUBLE_EQ(c->tuning.revisit_look_altitude_m, 18.0);
  EXPECT_DOUBLE_EQ(c->tuning.fusion.close_look_height_m, 21.0);
  ctx.args["revisit_look_altitude_m"] = "20";
  c = SarBrainConfigFrom(ctx);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().ToString().find("revisit_look_altitude_m must be 0 or"), std::string::npos)
      << c.error().ToString();
  ctx.args["revisit_look_altitude_m"] = "0";
  ctx.args["fusion_close_look_height_m"] = "0";
  c = SarBrainConfigFrom(ctx);
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  EXPECT_DOUBLE_EQ(c->tuning.fusion.close_look_height_m, 0.0);
}

TEST(SarBrainConfigFrom, NamesTheBadArgOrPayload) {
  brain::Context ctx = LifterContext();
  ctx.args["member_timeout_s"] = "six";
  auto c = SarBrainConfigFrom(ctx);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().ToString().find("member_timeout_s 'six'"), std::string::npos) << c.error().ToString();
  ctx = LifterContext();
  ctx.args["start"] = "0,-10";
  c = SarBrainConfigFrom(ctx);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().ToString().find("start '0,-10'"), std::string::npos) << c.error().ToString();
  ctx = LifterContext();
  ctx.args["search_margin_m"] = "-5";  // lanes outside the geofence
  c = SarBrainConfigFrom(ctx);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().ToString().find("search_margin_m must be >= 0"), std::string::npos)
      << c.error().ToString();
  ctx = LifterContext();
  ctx.payload = "piano";
  c = SarBrainConfigFrom(ctx);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().ToString().find("--payload 'piano'"), std::string::npos) << c.error().ToString();
}

SarBrainConfig Scout(const std::string& name, std::vector<std::string> members) {
  SarBrainConfig c;
  c.name = name;
  c.members = std::move(members);
  c.airframe = "x500";
  c.has_home = true;
  c.home_m = Vec3(0, 0, 0);
  return c;
}

TEST(SarBrainCreate, RejectsBadConfigurations) {
  SarBrainConfig c = Scout("scout_9", {"scout_1"});
  auto r = SarBrain::Create(c);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().ToString().find("does not include 'scout_9'"), std::string::npos);
  c = Scout("scout_1", {"scout_1"});
  c.airframe = "glider";
  r = SarBrain::Create(c);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().ToString().find("battery"), std::string::npos) << r.error().ToString();
  c = Scout("scout_1", {"scout_1"});
  c.geofence_size_x_m = 10.0;
  c.tuning.search_margin_m = 5.0;  // nothing left to search
  r = SarBrain::Create(c);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().ToString().find("too small"), std::string::npos);
}

// What the brain asked the flight stack for, in one shape: a command (takeoff, land) or a
// setpoint (position only, or velocity only with the position unset).
struct Sent {
  std::string kind;  // "takeoff", "land", "position", "velocity"
  Vec3 value = Vec3::Zero();
};

// A brain stepped at the lockstep rate as BrainHost does: the estimate the test moves by hand,
// the neighbour table (latest state heard from each drone, sorted by name), the committed
// mission in the brain's own ReplicatedState, and, when asked for, netem's wall-clock side channel.
class BrainRig {
 public:
  explicit BrainRig(const SarBrainConfig& c, bool netem_wall = false)
      : brain_(*SarBrain::Create(c, {}, netem_wall ? &wall_ : nullptr)), state_(brain_->MakeReplicatedState()) {}
  const brain::Output& Step(std::string_view mode, bool leader = false, bool hover = false, double mass_kg = 0) {
    t_ns_ += 4'000'000;
    wall_.now_s += 0.004 / speed_up_;
    out_ = brain::Output{};
    brain::Input in;
    in.t_ns = t_ns_;
    in.self.name = "self";
    in.self.position_m = {pos_.x(), pos_.y(), pos_.z()};
    in.self.flight_mode = std::string(mode);
    in.self.landed = mode == "idle" || mode == "landed";
    in.self.mass_estimate_kg = mass_kg;
    events_.clear();
    if (hover) events_.push_back({"hover", t_ns_, {}});
    in.flight_events = events_;
    in.is_leader = leader;
    table_.clear();
    for (const auto& [name, n] : heard_) table_.push_back(n);
    in.neighbours = table_;
    in.messages = inbox_;
    in.state = state_.get();
    brain_->Step(in, out_);
    inbox_.clear();
    for (const brain::Message& m : out_.messages) sent_messages_.push_back(m);
    EXPECT_EQ(out_.status, brain_->mode());
    return out_;
  }
  // Steps `seconds` and returns everything asked of the flight stack meanwhile.
  std::vector<Sent> Run(double seconds, std::string_view mode, bool leader = false) {
    std::vector<Sent> sent;
    for (const std::int64_t end = t_ns_ + static_cast<std::int64_t>(seconds * 1e9); t_ns_ < end;) {
      const brain::Output& out = Step(mode, leader);
      for (const brain::Command& c : out.commands) {
        if (c.kind == brain::Command::Kind::kTakeoff) sent.push_back({"takeoff", Vec3(0, 0, c.param)});
        if (c.kind == brain::Command::Kind::kLand) sent.push_back({"land", Vec3::Zero()});
      }
      for (const brain::Setpoint& sp : out.setpoint) {
        const bool position = std::isfinite(sp.position_m.x);
        EXPECT_NE(position, std::isfinite(sp.velocity_m_s.x)) << "position only, or velocity only";
        EXPECT_TRUE(std::isnan(sp.acceleration_m_s2.x));
        const brain::Vec3& v = position ? sp.position_m : sp.velocity_m_s;
        sent.push_back({position ? "position" : "velocity", Vec3(v.x, v.y, v.z)});
      }
      for (const std::vector<std::uint8_t>& bytes : out.proposals) {
        auto c = raft::DecodeCommand(bytes);
        EXPECT_TRUE(c.ok());
        if (c.ok()) proposals_.push_back(*c);
      }
    }
    return sent;
  }
  // A DroneState of `name` heard now (netem: received now on the wall clock as well).
  void Hear(const std::string& name, const std::string& status, const Vec3& pos, double sent_s) {
    brain::Neighbour n;
    n.name = name;
    n.status = status;
    n.position_m = {pos.x(), pos.y(), pos.z()};
    n.t_ns = static_cast<std::int64_t>(std::llround(sent_s * 1e9));
    heard_[name] = n;
    wall_.OnState(name, n.t_ns, wall_.now_s);
  }
  // A brain message delivered at the next Step.
  void Tell(const std::string& from, const std::string& topic, const std::string& payload) {
    inbox_.push_back({from, "", topic, std::vector<std::uint8_t>(payload.begin(), payload.end())});
  }
  std::vector<brain::Message>& sent_messages() { return sent_messages_; }
  void Commit(const raft::MissionCommand& c) { state_->Apply(++index_, raft::EncodeCommand(c)); }
  // The world runs `speed_up` times faster than the wall clock (1: rtf 1; ~8 at rtf 0 on
  // loopback); only read by a brain made with netem_wall.
  void SetSpeedUp(double speed_up) { speed_up_ = speed_up; }
  SarBrain& brain() { return *brain_; }
  Vec3& position() { return pos_; }
  const raft::MissionState& mission() const { return dynamic_cast<const SarMissionState&>(*state_).mission(); }
  std::vector<raft::MissionCommand>& proposals() { return proposals_; }

 private:
  NetemWallClock wall_{.now_s = 100.0, .heard = {}};  // any monotonic origin
  std::unique_ptr<SarBrain> brain_;
  std::unique_ptr<brain::ReplicatedState> state_;
  brain::Output out_;
  std::vector<brain::FlightEvent> events_;
  std::map<std::string, brain::Neighbour> heard_;
  std::vector<brain::Neighbour> table_;
  std::vector<raft::MissionCommand> proposals_;
  std::vector<brain::Message> inbox_, sent_messages_;
  Vec3 pos_ = Vec3::Zero();
  std::int64_t t_ns_ = 0;
  std::uint64_t index_ = 0;
  double speed_up_ = 1.0;
};

TEST(SarBrainScout, TakesOffShortThenClimbsInPositionModeAndPublishesItsMode) {
  BrainRig rig(Scout("scout_1", {"scout_1"}));
  rig.position() = Vec3(0, 0, 0.23);
  const brain::Output& first = rig.Step("idle");
  EXPECT_TRUE(HasEvent(first, "mission_start"));
  EXPECT_EQ(first.status, "scout/on_ground");
  std::vector<Sent> sent = rig.Run(1.5, "idle");
  EXPECT_TRUE(sent.empty());  // 2 s on the ground first (the estimator settles)
  sent = rig.Run(1.0, "idle");  // (re-sent each tick while the drone stays idle)
  ASSERT_FALSE(sent.empty());
  for (const Sent& sp : sent) {
    EXPECT_EQ(sp.kind, "takeoff");
    EXPECT_DOUBLE_EQ(sp.value.z(), 3.0);  // the short flight-stack take-off
  }
  EXPECT_EQ(rig.brain().mode(), "scout/taking_off");
  rig.position() = Vec3(0, 0, 3.2);
  sent = rig.Run(1.0, "takeoff");
  EXPECT_TRUE(sent.empty());
  sent = rig.Run(0.5, "hold");  // take-off height reached: the flight stack holds
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_EQ(sent[0].kind, "position");
  EXPECT_EQ(sent[0].value, Vec3(0, 0, 30));  // then the climb to the search altitude
}

// A trial's mission.tuning reaches the brain as --mission-tuning's JSON: its numbers are Context
// args (SarBrainConfigFrom reads them as any other), so a low search altitude is the scout's climb.
TEST(SarBrainMissionTuning, TheTrialsScoutAltitudeIsTheScoutsClimb) {
  auto tuning = ParseMissionTuning(R"({"scout_altitude_m": 12, "scout_min_clearance_m": 5})");
  ASSERT_TRUE(tuning.ok()) << tuning.error().ToString();
  brain::Context ctx = LifterContext();
  ctx.args = *tuning;
  auto c = SarBrainConfigFrom(ctx);
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  EXPECT_DOUBLE_EQ(c->tuning.scout_altitude_m, 12.0);
  EXPECT_DOUBLE_EQ(c->tuning.scout_min_clearance_m, 5.0);
  EXPECT_DOUBLE_EQ(c->tuning.member_timeout_s, MissionTuning{}.member_timeout_s);  // untouched

  SarBrainConfig scout = Scout("scout_1", {"scout_1"});
  scout.tuning = c->tuning;
  BrainRig rig(scout);
  rig.position() = Vec3(0, 0, 0.23);
  rig.Run(2.5, "idle");  // on the ground, then the short take-off
  rig.position() = Vec3(0, 0, 3.2);
  rig.Run(1.0, "takeoff");
  const std::vector<Sent> sent = rig.Run(0.5, "hold");
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_EQ(sent[0].kind, "position");
  EXPECT_EQ(sent[0].value, Vec3(0, 0, 12));  // the trial's search altitude, not the default 30 m
}

TEST(SarBrainMissionTuning, EveryKeyIsATuningNumberAndNoneIsStart) {
  const std::vector<std::string> keys = SarTuningKeys();
  EXPECT_EQ(std::count(keys.begin(), keys.end(), "scout_altitude_m"), 1);
  EXPECT_EQ(std::count(keys.begin(), keys.end(), "fusion_confirm_views"), 1);
  EXPECT_EQ(std::count(keys.begin(), keys.end(), "start"), 0);
  // Every key the parser accepts is one SarBrainConfigFrom reads: a number it reads as such.
  brain::Context ctx = LifterContext();
  for (const std::string& key : keys) ctx.args[key] = "not_a_number";
  for (const std::string& key : keys) {
    auto c = SarBrainConfigFrom(ctx);
    ASSERT_FALSE(c.ok()) << key;
    EXPECT_NE(c.error().ToString().find("arg " + key + " 'not_a_number'"), std::string::npos) << c.error().ToString();
    ctx.args.erase(key);
  }
}

TEST(SarBrainMissionTuning, NamesAnUnknownKeyAndTheKnownOnesAndRefusesNonNumbers) {
  auto unknown = ParseMissionTuning(R"({"scout_altitude_m": 12, "scout_altitud_m": 12})");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code(), ErrorCode::kInvalidArgument);
  const std::string text = unknown.error().ToString();
  EXPECT_NE(text.find("--mission-tuning: unknown key 'scout_altitud_m'; the SAR mission tunes mission_dt_s, "),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("scout_altitude_m, "), std::string::npos) << text;
  EXPECT_NE(text.find("fusion_max_revisits"), std::string::npos) << text;
  auto start = ParseMissionTuning(R"({"start": "0,0,0"})");  // the take-off spot is --start's
  ASSERT_FALSE(start.ok());
  EXPECT_NE(start.error().ToString().find("unknown key 'start'"), std::string::npos) << start.error().ToString();
  auto word = ParseMissionTuning(R"({"scout_altitude_m": "low"})");
  ASSERT_FALSE(word.ok());
  EXPECT_NE(word.error().ToString().find("--mission-tuning: scout_altitude_m 'low': expected a number"),
            std::string::npos)
      << word.error().ToString();
  auto nested = ParseMissionTuning(R"({"scout_altitude_m": {"m": 12}})");
  ASSERT_FALSE(nested.ok());
  EXPECT_NE(nested.error().ToString().find("expected a number"), std::string::npos) << nested.error().ToString();
  auto list = ParseMissionTuning("[12]");
  ASSERT_FALSE(list.ok());
  EXPECT_NE(list.error().ToString().find("--mission-tuning"), std::string::npos) << list.error().ToString();
  auto none = ParseMissionTuning("");
  ASSERT_TRUE(none.ok()) << none.error().ToString();
  EXPECT_TRUE(none->empty());
}

TEST(SarBrainScout, TheHoverEventAloneStartsTheClimb) {
  BrainRig rig(Scout("scout_1", {"scout_1"}));
  rig.position() = Vec3(0, 0, 0.23);
  rig.Run(2.5, "idle");
  rig.position() = Vec3(0, 0, 3.2);
  EXPECT_TRUE(rig.Run(0.2, "takeoff").empty());
  bool climb = false;
  // The flight event `hover` while the mode still reads takeoff (the behaviours look at it on
  // their 10 Hz tick: one tick's worth of steps reporting it): the climb follows.
  for (int k = 0; k < 25 && !climb; ++k) climb = !rig.Step("takeoff", false, /*hover=*/true).setpoint.empty();
  EXPECT_TRUE(climb);
}

TEST(SarBrainScout, AloneAndLeadingItAssignsItselfTheWholeSearchAreaAndStarts) {
  BrainRig rig(Scout("scout_1", {"scout_1"}));
  rig.position() = Vec3(0, 0, 0.23);
  rig.Run(2.5, "idle", /*leader=*/true);
  EXPECT_TRUE(rig.proposals().empty());  // on the ground: no search yet
  rig.position() = Vec3(0, 0, 29.5);
  rig.Run(0.5, "position", true);
  ASSERT_EQ(rig.proposals().size(), 2u);
  const auto* assign = std::get_if<raft::AssignSectors>(&rig.proposals()[0]);
  ASSERT_NE(assign, nullptr);
  ASSERT_EQ(assign->sectors.size(), 1u);
  // The 200 x 200 m geofence (the search margin is 0: the whole field).
  EXPECT_DOUBLE_EQ(assign->sectors[0].x_min_m, -100.0);
  EXPECT_DOUBLE_EQ(assign->sectors[0].y_max_m, 100.0);
  EXPECT_TRUE(std::holds_alternative<raft::StartSearch>(rig.proposals()[1]));
  // Committed: it flocks along its first lane (a velocity setpoint every mission tick).
  rig.Commit(rig.proposals()[0]);
  rig.Commit(rig.proposals()[1]);
  EXPECT_EQ(rig.mission().phase(), raft::MissionPhase::kSearch);
  rig.position() = Vec3(0, 0, 30);
  const std::vector<Sent> sent = rig.Run(1.0, "velocity", true);
  ASSERT_GE(sent.size(), 9u);
  EXPECT_EQ(sent.back().kind, "velocity");
  EXPECT_EQ(rig.brain().mode(), "scout/searching");
}

TEST(SarBrainScout, WaitsForEveryMemberBeforeStartingAndReadsTheirRoles) {
  BrainRig rig(Scout("scout_1", {"scout_1", "lifter"}));
  rig.position() = Vec3(0, 0, 0.23);
  rig.Run(3.0, "idle");
  EXPECT_EQ(rig.brain().mode(), "scout/on_ground");  // not started: the lifter is unheard
  rig.Hear("lifter", "lifter/on_ground", Vec3(0, -10, 0.6), 3.0);
  rig.Hear("ground_station", "scout/on_ground", Vec3::Zero(), 3.0);  // not a member: ignored
  const brain::Output& out = rig.Step("idle");
  ASSERT_TRUE(HasEvent(out, "mission_start"));
  EXPECT_EQ(out.events.front().name, "mission_start");
  EXPECT_EQ(Field(out.events.front(), "lifter_present"), "true");
}

// The leader's roster ages each peer on the simulated clock: a scout whose DroneState stops is
// gone after member_timeout_s (6 s) and its committed sector is handed over through Raft.
TEST(SarBrainScout, LeadingItHandsASilentPeersSectorOverAfterTheMemberTimeout) {
  BrainRig rig(Scout("scout_1", {"scout_1", "scout_2"}));
  rig.Commit(raft::AssignSectors{{{"scout_1", -92, -92, 0, 92}, {"scout_2", 0, -92, 92, 92}}});
  rig.Commit(raft::StartSearch{});
  rig.position() = Vec3(0, 0, 30);
  const auto handed_over = [&] {
    for (const raft::MissionCommand& c : rig.proposals()) {
      if (std::holds_alternative<raft::AssignSectors>(c)) return true;
    }
    return false;
  };
  for (double t = 0.0; t < 10.0; t += 0.5) {  // heard at 5 Hz (every other half second here)
    rig.Hear("scout_2", "scout/searching", Vec3(50, 0, 30), t);
    rig.Run(0.5, "velocity", /*leader=*/true);
  }
  EXPECT_FALSE(handed_over());
  rig.Run(5.0, "velocity", true);  // last state taken at 9.5 s: 5.5 s of silence
  EXPECT_FALSE(handed_over());
  rig.Run(1.5, "velocity", true);
  ASSERT_TRUE(handed_over());
  for (const raft::MissionCommand& c : rig.proposals()) {
    const auto* a = std::get_if<raft::AssignSectors>(&c);
    if (a == nullptr) continue;
    for (const raft::Sector& sector : a->sectors) EXPECT_EQ(sector.drone, "scout_1");
    EXPECT_EQ(a->sectors.size(), 2u);
  }
}

// netem's side channel (the node stamps each DroneState when it takes it off the radio): at rtf
// 0 the world runs ~10x faster than the radio delivers, so 6 s of simulated silence is 0.6 s of
// wall time, a delayed sample, not a lost drone; the sector goes over once the peer is also 3 s
// silent on the wall clock. At rtf 1 the 6 s simulated timeout decides, as without wall times.
TEST(SarBrainScout, AtRtf0APeerIsLostOnlyWhenAlsoSilentOnTheWallClock) {
  for (const double speed_up : {10.0, 1.0}) {
    SCOPED_TRACE("speed-up " + std::to_string(speed_up));
    BrainRig rig(Scout("scout_1", {"scout_1", "scout_2"}), /*netem_wall=*/true);
    rig.SetSpeedUp(speed_up);
    rig.Commit(raft::AssignSectors{{{"scout_1", -92, -92, 0, 92}, {"scout_2", 0, -92, 92, 92}}});
    rig.Commit(raft::StartSearch{});
    rig.position() = Vec3(0, 0, 30);
    const auto handed_over = [&] {
      for (const raft::MissionCommand& c : rig.proposals()) {
        if (std::holds_alternative<raft::AssignSectors>(c)) return true;
      }
      return false;
    };
    for (double t = 0.0; t < 10.0; t += 0.5) {
      rig.Hear("scout_2", "scout/searching", Vec3(50, 0, 30), t);
      rig.Run(0.5, "velocity", /*leader=*/true);
    }
    rig.Run(5.0, "velocity", true);  // last state taken at 9.5 s: 5.5 s of silence
    EXPECT_FALSE(handed_over());
    rig.Run(1.5, "velocity", true);  // 7 s simulated: 7 s wall at rtf 1, 0.7 s at 10x
    if (speed_up == 1.0) {
      EXPECT_TRUE(handed_over());
      continue;
    }
    EXPECT_FALSE(handed_over());
    rig.Run(21.0, "velocity", true);  // 28 s simulated, 2.8 s wall
    EXPECT_FALSE(handed_over());
    rig.Run(3.0, "velocity", true);   // 31 s simulated, 3.1 s wall
    EXPECT_TRUE(handed_over());
  }
}

// Without the side channel (the simulated channel, any library host) the same speed-up does not
// matter: the simulated rule alone decides, after 6 s.
TEST(SarBrainScout, WithoutTheSideChannelTheSimulatedRuleDecidesAlone) {
  BrainRig rig(Scout("scout_1", {"scout_1", "scout_2"}));
  rig.SetSpeedUp(10.0);
  rig.Commit(raft::AssignSectors{{{"scout_1", -92, -92, 0, 92}, {"scout_2", 0, -92, 92, 92}}});
  rig.Commit(raft::StartSearch{});
  rig.position() = Vec3(0, 0, 30);
  for (double t = 0.0; t < 10.0; t += 0.5) {
    rig.Hear("scout_2", "scout/searching", Vec3(50, 0, 30), t);
    rig.Run(0.5, "velocity", /*leader=*/true);
  }
  rig.Run(7.0, "velocity", true);
  bool handed_over = false;
  for (const raft::MissionCommand& c : rig.proposals()) handed_over = handed_over || std::holds_alternative<raft::AssignSectors>(c);
  EXPECT_TRUE(handed_over);
}

TEST(StatusMessage, RoundTripsAndRejectsGarbage) {
  const std::string text = EncodeStatusMessage(12'345'000'000, "scout/searching", -12.5, 300.25);
  EXPECT_EQ(text, "12345000000 scout/searching -12.50 300.25");
  std::int64_t t_ns = 0;
  std::string status;
  double x = 0, y = 0;
  ASSERT_TRUE(DecodeStatusMessage(text, &t_ns, &status, &x, &y));
  EXPECT_EQ(t_ns, 12'345'000'000);
  EXPECT_EQ(status, "scout/searching");
  EXPECT_DOUBLE_EQ(x, -12.5);
  EXPECT_DOUBLE_EQ(y, 300.25);
  for (const char* bad :
       {"", "1 scout/searching 1", "1 scout/searching 1 2 3", "x scout/searching 1 2", "1 pilot/x 1 2",
        "1 scout/searching 1 nan", "1  scout/searching 1 2", "1 scout/searching 1 2 "}) {
    EXPECT_FALSE(DecodeStatusMessage(bad, &t_ns, &status, &x, &y)) << "'" << bad << "'";
  }
}

// Every member broadcasts its status (kStatusTopic): at once on a change of stage, else every
// status_every_s (1 s), so that a leader that does not get it among its nearest neighbours
// still knows it.
TEST(SarBrainScout, BroadcastsItsStatusOnEachChangeAndEverySecond) {
  BrainRig rig(Scout("scout_1", {"scout_1"}));
  rig.position() = Vec3(0, 0, 0.23);
  rig.Run(2.9, "idle");
  std::vector<std::string> texts;
  for (const brain::Message& m : rig.sent_messages()) {
    EXPECT_EQ(m.topic, kStatusTopic);
    EXPECT_EQ(m.to, "");  // a broadcast: every member keeps its table
    texts.emplace_back(m.payload.begin(), m.payload.end());
  }
  // 0 s (first word), 1 s, 2 s on the ground; at 2 s + a tick the take-off (a change) at once.
  ASSERT_EQ(texts.size(), 4u);
  EXPECT_NE(texts[0].find(" scout/on_ground 0.00 0.00"), std::string::npos) << texts[0];
  EXPECT_NE(texts[2].find(" scout/on_ground "), std::string::npos) << texts[2];
  EXPECT_NE(texts[3].find(" scout/taking_off "), std::string::npos) << texts[3];
}

// A member the leader hears only through status messages (never among its neighbours, as at 100
// drones when it is not among the nearest 32) counts as heard and gets its sector.
TEST(SarBrainScout, TheLeaderKnowsAMemberHeardOnlyThroughItsStatusMessages) {
  BrainRig rig(Scout("scout_1", {"scout_1", "scout_2"}));
  rig.position() = Vec3(0, 0, 0.23);
  rig.Run(3.0, "idle", /*leader=*/true);
  EXPECT_EQ(rig.brain().mode(), "scout/on_ground");  // scout_2 unheard: not started
  rig.Tell("scout_2", std::string(kStatusTopic),
           EncodeStatusMessage(3'000'000'000, "scout/on_ground", 400, 0));
  rig.Tell("ground", std::string(kStatusTopic), EncodeStatusMessage(3'000'000'000, "scout/on_ground", 0, 0));
  rig.Step("idle", true);
  rig.Run(3.0, "idle", true);
  EXPECT_EQ(rig.brain().mode(), "scout/taking_off");  // started: every member heard
  rig.position() = Vec3(0, 0, 30);
  for (double t = 6.0; t < 8.0; t += 0.5) {
    rig.Tell("scout_2", std::string(kStatusTopic),
             EncodeStatusMessage(static_cast<std::int64_t>(t * 1e9), "scout/awaiting_sector", 400, 0));
    rig.Run(0.5, "position", true);
  }
  const raft::AssignSectors* assign = nullptr;
  for (const raft::MissionCommand& c : rig.proposals()) {
    if (const auto* a = std::get_if<raft::AssignSectors>(&c)) assign = a;
  }
  ASSERT_NE(assign, nullptr);
  ASSERT_EQ(assign->sectors.size(), 2u);
  // Strips in the order of where they are: scout_2 (x = 400 m) east of scout_1 (x = 0).
  EXPECT_EQ(assign->sectors[0].drone, "scout_1");
  EXPECT_EQ(assign->sectors[1].drone, "scout_2");
}

// The leader logs how the swarm flocks (agent/swarm flock_metrics.hpp) from its member table once
// per simulated second; a follower does not.
TEST(SarBrainScout, TheLeaderLogsFlockMetricsFromItsMemberTableOncePerSecond) {
  for (const bool leader : {true, false}) {
    BrainRig rig(Scout("scout_1", {"scout_1", "scout_2"}));
    rig.position() = Vec3(0, 0, 0.23);
    rig.Tell("scout_2", std::string(kStatusTopic), EncodeStatusMessage(0, "scout/on_ground", 6, 8));
    std::vector<brain::Event> lines;
    for (int step = 0; step < 875; ++step) {  // 3.5 s
      for (const brain::Event& e : rig.Step("idle", leader).events) {
        if (e.name == "flock_metrics") lines.push_back(e);
      }
    }
    if (!leader) {
      EXPECT_TRUE(lines.empty());
      continue;
    }
    // At the first mission tick (4 ms), then 1.004, 2.004 and 3.004 s.
    ASSERT_EQ(lines.size(), 4u);
    EXPECT_EQ(Field(lines[0], "members"), "2");
    EXPECT_EQ(Field(lines[0], "safety"), "1.000");  // 10 m apart
    EXPECT_EQ(Field(lines[0], "min_m"), "10.00");
    EXPECT_EQ(Field(lines[3], "union"), "1.000");
  }
}

TEST(SarBrainLifter, TheLoadCheckDropsAnAttachTheWorldDidNotCarryOut) {
  SarBrainConfig c;
  c.name = "lifter";
  c.members = {"lifter"};
  c.airframe = "x8_heavy";
  c.payload = "stretcher";
  c.base_height_m = 0.6;
  c.vehicle_mass_kg = 120.0;
  c.has_home = true;
  c.payload_offset_m = Eigen::Vector2d(0, -3);
  BrainRig rig(c);
  // A rescue for this lifter is committed.
  rig.Commit(raft::AssignSectors{{{"scout_1", -50, -50, 50, 50}}});
  rig.Commit(raft::StartSearch{});
  rig.Commit(raft::ConfirmVictim{"operator", 40, 0});
  rig.Commit(raft::ConvergeOn{1});
  rig.Commit(raft::BeginRescue{1, "lifter"});
  ASSERT_EQ(rig.mission().phase(), raft::MissionPhase::kRescue);
  rig.position() = Vec3(0, 0, 0.6);
  rig.Run(0.2, "idle");
  EXPECT_EQ(rig.brain().mode(), "lifter/takeoff_for_pickup");
  // Hover settled over the stretcher at the hook height: the attach goes out as a command.
  rig.position() = Vec3(0, -3, 4.525);
  bool attach = false;
  for (int k = 0; k < 1000 && !attach; ++k) {
    const brain::Output& out = rig.Step("position");
    for (const brain::Command& cmd : out.commands) {
      if (cmd.kind != brain::Command::Kind::kPayloadAttach) continue;
      attach = true;
      EXPECT_DOUBLE_EQ(cmd.param, 15.0);
    }
  }
  ASSERT_TRUE(attach);
  EXPECT_TRUE(rig.brain().payload_attached());
  // Climbing 4 m higher, 5 s later, the flight stack still feels only the empty airframe.
  rig.position() = Vec3(0, -3, 8.6);
  bool missing = false;
  for (int k = 0; k < 2000 && !missing; ++k) missing = HasEvent(rig.Step("position", false, false, 120.5), "payload_missing");
  ASSERT_TRUE(missing);
  EXPECT_FALSE(rig.brain().payload_attached());
  rig.Run(0.3, "position");
  EXPECT_EQ(rig.brain().mode(), "lifter/takeoff_for_pickup");  // back over the stretcher
}

// The ReplicatedState is the mission: its snapshot restores an equal state on another brain,
// and bytes that are not a snapshot are refused.
TEST(SarMissionState, SnapshotRestoresTheCommittedMissionAndRefusesGarbage) {
  BrainRig rig(Scout("scout_1", {"scout_1"}));
  rig.Commit(raft::AssignSectors{{{"scout_1", -92, -92, 92, 92}}});
  rig.Commit(raft::StartSearch{});
  rig.Commit(raft::ConfirmVictim{"operator", 40, 0});
  auto other = (*SarBrain::Create(Scout("scout_1", {"scout_1"})))->MakeReplicatedState();
  std::unique_ptr<brain::ReplicatedState> copy = rig.brain().MakeReplicatedState();
  // The rig's own state holds the three entries; a fresh state of another brain takes its snapshot.
  const auto& held = rig.mission();
  ASSERT_EQ(held.victims().size(), 1u);
  SarMissionState restored({});
  ASSERT_TRUE(restored.Restore(held.EncodeSnapshot()));
  EXPECT_EQ(restored.mission(), held);
  EXPECT_EQ(restored.Snapshot(), held.EncodeSnapshot());
  const std::vector<std::uint8_t> garbage = {0xff, 0x00, 0x13};
  EXPECT_FALSE(other->Restore(garbage));
  // Entries that do not decode change nothing, the same way everywhere.
  copy->Apply(1, garbage);
  EXPECT_EQ(dynamic_cast<const SarMissionState&>(*copy).mission().phase(), raft::MissionPhase::kIdle);
}

// The agent's wiring in small: SarBrain inside BrainHost with a fake flight stack and consensus,
// its state applied as Raft would. The take-off is a flight-stack take-off, the climb a Position
// kind, the lane a Velocity kind (FromTrajectory keeps the smoothed kinds for position-only and
// velocity-only setpoints); the leader's proposals reach the consensus as MissionCommands.
class RecordingFlight final : public FlightPort {
 public:
  bool Command(const flight::Setpoint& sp) override {
    kinds.push_back(sp.kind);
    values.push_back(sp.value);
    return true;
  }
  void SetPayloadMass(double /*kg*/) override {}
  std::vector<flight::Setpoint::Kind> kinds;
  std::vector<Vec3> values;
};

class LeadingConsensus final : public ConsensusPort {
 public:
  bool is_leader() const override { return true; }
  std::string leader() const override { return "scout_1"; }
  void TakeCommitted(std::vector<brain::Entry>* /*out*/) override {}
  bool Propose(std::span<const std::uint8_t> data) override {
    auto c = raft::DecodeCommand(data);
    EXPECT_TRUE(c.ok());
    if (c.ok()) proposals.push_back(*c);
    return true;
  }
  std::vector<raft::MissionCommand> proposals;
};

TEST(SarBrainOnBrainHost, TakesOffClimbsAndSearchesThroughTheHostAlone) {
  auto made = SarBrain::Create(Scout("scout_1", {"scout_1"}));
  ASSERT_TRUE(made.ok());
  SarBrain* sar = made->get();
  std::unique_ptr<SarMissionState> state = sar->MakeMissionState();
  RecordingFlight flight;
  LeadingConsensus consensus;
  BrainHostOptions bo;
  bo.self = "scout_1";
  bo.state = state.get();
  BrainHost host(bo, std::move(*made), flight, nullptr, &consensus, nullptr);
  brain::Vehicle v;
  std::uint64_t step = 0;
  std::vector<bus::WorldCommand> world;
  const auto run = [&](double seconds, const std::string& mode, double z) {
    v.flight_mode = mode;
    v.landed = mode == "idle";
    v.position_m = {0, 0, z};
    for (const std::uint64_t end = step + static_cast<std::uint64_t>(seconds / 0.004); step < end;) {
      ++step;
      host.Step(step, static_cast<std::int64_t>(step) * 4'000'000, v, &world);
    }
  };
  run(2.5, "idle", 0.23);
  ASSERT_FALSE(flight.kinds.empty());
  EXPECT_EQ(flight.kinds.front(), flight::Setpoint::Kind::kTakeoff);
  EXPECT_DOUBLE_EQ(flight.values.front().z(), 3.0);
  EXPECT_EQ(host.status(), "scout/taking_off");
  flight.kinds.clear();
  flight.values.clear();
  run(0.5, "hold", 3.2);
  ASSERT_EQ(flight.kinds.size(), 1u);
  EXPECT_EQ(flight.kinds[0], flight::Setpoint::Kind::kPosition);
  EXPECT_EQ(flight.values[0], Vec3(0, 0, 30));
  run(0.5, "position", 29.5);
  ASSERT_EQ(consensus.proposals.size(), 2u);
  std::uint64_t index = 0;
  for (const raft::MissionCommand& c : consensus.proposals) state->Apply(++index, raft::EncodeCommand(c));  // as Raft
  EXPECT_EQ(state->mission().phase(), raft::MissionPhase::kSearch);
  run(1.0, "velocity", 30.0);
  EXPECT_EQ(flight.kinds.back(), flight::Setpoint::Kind::kVelocity);
  EXPECT_EQ(host.status(), "scout/searching");
  EXPECT_TRUE(world.empty());  // a scout has no payload
}

}  // namespace
}  // namespace swarmbox::agent
