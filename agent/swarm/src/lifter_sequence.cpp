#include "swarmbox/swarm/lifter_sequence.hpp"

#include <cmath>
#include <utility>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {

using raft::MissionPhase;
using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

namespace {

constexpr double kSlowSpeed_m_s = 0.5;          // vertical legs near the ground
constexpr double kTakeoffUntilAboveBase_m = 1.5;  // take off (not position hold) below this
constexpr double kClimbDoneTolerance_m = 1.0;     // a climb ends this close to transit altitude
constexpr double kLandingPointAboveAttach_m = 1.0;  // the move to the landing point stays this high
constexpr double kLandingPointSpeed_m_s = 0.5;  // over the landing point: slower than this
constexpr double kOnGroundAboveBase_m = 0.15;   // touched down: body this close to base height
constexpr double kOnGroundSpeed_m_s = 0.3;
// The survey's depth image needs the camera near survey_height_m, not exactly there: 1 m is 12 %
// of the ground resolution at 8 m.
constexpr double kSurveyHeightTolerance_m = 1.0;

Vec3 At(const Vec2& xy_m, double z_m) { return {xy_m.x(), xy_m.y(), z_m}; }

}  // namespace

std::string_view LifterSequence::StageName(Stage stage) {
  switch (stage) {
    case Stage::kOnGround: return "on_ground";
    case Stage::kTakeoffForPickup: return "takeoff_for_pickup";
    case Stage::kAttachEmpty: return "attach_empty";
    case Stage::kClimbToTransit: return "climb";
    case Stage::kTransitToVictim: return "transit_to_victim";
    case Stage::kSurveyDropPoint: return "survey_drop_point";
    case Stage::kDescendToRelease: return "descend_to_release";
    case Stage::kRelease: return "release";
    case Stage::kWaitLoading: return "loading";
    case Stage::kAttachLoaded: return "attach_loaded";
    case Stage::kClimbWithLoad: return "climb_loaded";
    case Stage::kCarryHome: return "carry_home";
    case Stage::kDescendToDrop: return "descend_to_drop";
    case Stage::kReleaseAtHome: return "release_at_home";
    case Stage::kMoveToLandingPoint: return "move_to_land";
    case Stage::kLanding: return "landing";
    case Stage::kStandby: return "standby";
  }
  return "?";
}

LifterSequence::LifterSequence(LifterConfig config)
    : config_(std::move(config)),
      stretcher_xy_m_(config_.home_m.head<2>() + config_.stretcher_start_offset_m) {
  SWARMBOX_CHECK(!config_.name.empty());
  SWARMBOX_CHECK(config_.sling_length_m > 0 && config_.transit_altitude_m > config_.AttachHeight());
  SWARMBOX_CHECK(config_.release_sink_m < config_.AttachHeight() &&
                 config_.transit_altitude_m > config_.AttachHeight() - config_.release_sink_m);
  // The surveyed stretcher must hang clear of the ground, below transit altitude.
  SWARMBOX_CHECK(!config_.survey_drop_point || (config_.survey_height_m > config_.AttachHeight() &&
                                                config_.survey_height_m <= config_.transit_altitude_m &&
                                                config_.survey_timeout_s > 0));
}

void LifterSequence::Enter(Stage stage, const MissionInput& in, MissionOutput* out) {
  if (stage == stage_) return;
  stage_ = stage;
  stage_start_s_ = in.t_s;
  settled_since_s_ = -1.0;
  last_request_s_ = -1e9;
  LogEvent e(in.t_s, config_.name, "mission_stage");
  e.Add("role", "lifter").Add("stage", StageName(stage));
  if (victim_ != 0) e.Add("victim", static_cast<std::int64_t>(victim_));
  out->events.push_back(std::move(e));
}

bool LifterSequence::Settled(const MissionInput& in, const Vec3& target_m, bool release) {
  const double xy_tol = release ? config_.release_tolerance_m : config_.position_tolerance_m;
  const double z_tol = release ? 2 * config_.altitude_tolerance_m : config_.altitude_tolerance_m;
  const double speed = release ? config_.release_speed_m_s : config_.settle_speed_m_s;
  const bool close = (in.position_m.head<2>() - target_m.head<2>()).norm() <= xy_tol &&
                     std::abs(in.position_m.z() - target_m.z()) <= z_tol && in.velocity_m_s.norm() <= speed;
  if (!close) {
    settled_since_s_ = -1.0;
    return false;
  }
  if (settled_since_s_ < 0) settled_since_s_ = in.t_s;
  return in.t_s - settled_since_s_ >= config_.settle_time_s;
}

void LifterSequence::Hold(const Vec3& target_m, double speed_m_s, bool damp, MissionOutput* out) const {
  out->setpoint.kind = SetpointKind::kPosition;
  out->setpoint.target_m = target_m;
  out->setpoint.max_speed_m_s = speed_m_s;
  out->setpoint.damp_swing = damp;
}

void LifterSequence::RequestPayload(const MissionInput& in, PayloadAction action, double mass_kg,
                                    MissionOutput* out) {
  if (in.t_s - last_request_s_ < config_.attach_retry_s) return;
  last_request_s_ = in.t_s;
  out->payload = {action, mass_kg};
  LogEvent e(in.t_s, config_.name, action == PayloadAction::kAttach ? "payload_attach_request"
                                                                    : "payload_release_request");
  if (action == PayloadAction::kAttach) e.Add("mass_kg", mass_kg, 1);
  out->events.push_back(std::move(e));
}

void LifterSequence::Step(const MissionInput& in, MissionOutput* out) {
  SWARMBOX_CHECK(in.mission != nullptr);
  out->Clear();
  RepeatMarkRescued(in, out);
  HandleBatteryLow(in, out);
  // A transition re-runs the new stage at once, so the setpoint always belongs to out.mode.
  for (int pass = 0; pass < 4; ++pass) {
    const Stage before = stage_;
    RunStage(in, out);
    if (stage_ == before) break;
  }
  out->mode = StageName(stage_);
}

// MarkRescued until it is committed (proposals can be lost with a leader change).
void LifterSequence::RepeatMarkRescued(const MissionInput& in, MissionOutput* out) {
  if (delivered_victim_ == 0) return;
  const raft::Victim* v = in.mission->FindVictim(delivered_victim_);
  if (v == nullptr || v->status == raft::VictimStatus::kRescued) {
    delivered_victim_ = 0;
  } else if (in.t_s - last_proposal_s_ >= config_.proposal_retry_s) {
    last_proposal_s_ = in.t_s;
    out->proposals.push_back(raft::MarkRescued{delivered_victim_});
  }
}

// Battery low: abandon what is not loaded yet and go home.
void LifterSequence::HandleBatteryLow(const MissionInput& in, MissionOutput* out) {
  if (!in.battery_low || battery_low_reported_ || stage_ == Stage::kOnGround) return;
  battery_low_reported_ = true;
  out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "battery_low")
                                      .Add("battery", in.battery_fraction, 3)
                                      .Add("distance_home_m", (in.position_m.head<2>() - HomeXy()).norm(), 1)));
  // Not loaded yet: abandon the rescue (the stretcher comes home if it still hangs below).
  // Loaded (kClimbWithLoad and later): already on the way home with the evacuee.
  const bool loaded = stage_ > Stage::kAttachLoaded ||
                      (stage_ == Stage::kAttachLoaded && in.payload_attached);
  if (loaded) return;
  out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "rescue_abandoned")
                                      .Add("victim", static_cast<std::int64_t>(victim_))
                                      .Add("reason", "battery_low")));
  victim_ = 0;
  Enter(in.payload_attached ? Stage::kCarryHome : Stage::kMoveToLandingPoint, in, out);
}

bool LifterSequence::TakeRescue(const MissionInput& in) {
  const raft::MissionState& m = *in.mission;
  const raft::Victim* v = m.FindVictim(m.target_victim());
  if (m.phase() != MissionPhase::kRescue || v == nullptr || v->status != raft::VictimStatus::kBeingRescued ||
      v->rescuer != config_.name || v->id == delivered_victim_ || in.battery_low) {
    return false;
  }
  victim_ = v->id;
  victim_xy_m_ = {v->x_m, v->y_m};
  Vec2 toward_home = HomeXy() - victim_xy_m_;
  toward_home = toward_home.norm() > 1e-6 ? Vec2(toward_home.normalized()) : Vec2(1, 0);
  drop_xy_m_ = victim_xy_m_ + config_.stretcher_offset_m * toward_home;
  return true;
}

void LifterSequence::RunStage(const MissionInput& in, MissionOutput* out) {
  SetpointRequest& sp = out->setpoint;
  sp = {};
  sp.yaw_rad = HoldsSurveyYaw() ? survey_yaw_rad_ : in.yaw_rad;
  sp.target_m = in.position_m;
  switch (stage_) {
    case Stage::kOnGround: return RunOnGround(in, out);
    case Stage::kStandby: return RunStandby(in, out);
    case Stage::kTakeoffForPickup: return RunTakeoffForPickup(in, out);
    case Stage::kAttachEmpty: return RunAttachEmpty(in, out);
    case Stage::kClimbToTransit:  // the load check found the hook empty: go back for it
      return RunClimb(in, Stage::kTakeoffForPickup, config_.cruise_speed_m_s, Stage::kTransitToVictim, out);
    case Stage::kTransitToVictim: return RunTransitToVictim(in, out);
    case Stage::kSurveyDropPoint: return RunSurveyDropPoint(in, out);
    case Stage::kDescendToRelease: return RunDescend(in, drop_xy_m_, Stage::kRelease, out);
    case Stage::kRelease: return RunRelease(in, out);
    case Stage::kWaitLoading: return RunWaitLoading(in, out);
    case Stage::kAttachLoaded: return RunAttachLoaded(in, out);
    case Stage::kClimbWithLoad:  // the evacuee's stretcher stayed on the ground
      return RunClimb(in, Stage::kAttachLoaded, kSlowSpeed_m_s, Stage::kCarryHome, out);
    case Stage::kCarryHome: return RunCarryHome(in, out);
    case Stage::kDescendToDrop: return RunDescend(in, HomeXy(), Stage::kReleaseAtHome, out);
    case Stage::kReleaseAtHome: return RunReleaseAtHome(in, out);
    case Stage::kMoveToLandingPoint: return RunMoveToLandingPoint(in, out);
    case Stage::kLanding: return RunLanding(in, out);
  }
}

bool LifterSequence::Arrived(const MissionInput& in, const Vec2& xy_m) const {
  return (in.position_m.head<2>() - xy_m).norm() <= config_.arrive_tolerance_m &&
         in.velocity_m_s.norm() < config_.arrive_speed_m_s;
}

void LifterSequence::RunOnGround(const MissionInput& in, MissionOutput* out) {
  out->setpoint.kind = SetpointKind::kIdle;
  if (TakeRescue(in)) Enter(Stage::kTakeoffForPickup, in, out);
}

void LifterSequence::RunStandby(const MissionInput& in, MissionOutput* out) {
  const raft::MissionState& m = *in.mission;
  Hold(At(stretcher_xy_m_, AttachZ()), kSlowSpeed_m_s, false, out);
  if (TakeRescue(in)) {  // over the stretcher already: settle, then hook it
    Enter(Stage::kTakeoffForPickup, in, out);
    return;
  }
  bool waiting = false;  // a confirmed victim nobody rescues yet
  for (const raft::Victim& v : m.victims()) waiting = waiting || v.status == raft::VictimStatus::kConfirmed;
  const bool over = m.phase() == MissionPhase::kReturn || m.phase() == MissionPhase::kComplete;
  if (!waiting || over || in.battery_low) Enter(Stage::kMoveToLandingPoint, in, out);
}

void LifterSequence::RunTakeoffForPickup(const MissionInput& in, MissionOutput* out) {
  const Vec3& p = in.position_m;
  const Vec3 pickup = At(stretcher_xy_m_, AttachZ());
  if (p.z() < Ground() + config_.base_height_m + kTakeoffUntilAboveBase_m) {
    out->setpoint.kind = SetpointKind::kTakeoff;
    out->setpoint.target_m = {p.x(), p.y(), AttachZ()};
  } else {
    Hold(pickup, kSlowSpeed_m_s, false, out);
  }
  if (Settled(in, pickup)) Enter(Stage::kAttachEmpty, in, out);
}

void LifterSequence::RunAttachEmpty(const MissionInput& in, MissionOutput* out) {
  Hold(At(stretcher_xy_m_, AttachZ()), kSlowSpeed_m_s, false, out);
  if (in.payload_attached) {
    Enter(Stage::kClimbToTransit, in, out);
  } else {
    RequestPayload(in, PayloadAction::kAttach, config_.empty_stretcher_mass_kg, out);
  }
}

// Climbs over the stretcher to transit altitude with the load damped; an empty hook sends the
// lifter back to `if_unhooked`.
void LifterSequence::RunClimb(const MissionInput& in, Stage if_unhooked, double speed_m_s, Stage next,
                              MissionOutput* out) {
  if (!in.payload_attached) {
    Enter(if_unhooked, in, out);
    return;
  }
  Hold(At(stretcher_xy_m_, TransitZ()), speed_m_s, true, out);
  if (std::abs(in.position_m.z() - TransitZ()) <= kClimbDoneTolerance_m) Enter(next, in, out);
}

void LifterSequence::RunTransitToVictim(const MissionInput& in, MissionOutput* out) {
  if (!in.payload_attached) {
    Enter(Stage::kTakeoffForPickup, in, out);
    return;
  }
  Hold(At(drop_xy_m_, TransitZ()), config_.cruise_speed_m_s, true, out);
  if (!Arrived(in, drop_xy_m_)) return;
  if (config_.survey_drop_point) {
    survey_asked_s_ = -1.0;
    survey_decided_ = false;
    Enter(Stage::kSurveyDropPoint, in, out);
  } else {
    Enter(Stage::kDescendToRelease, in, out);
  }
}

bool LifterSequence::HoldsSurveyYaw() const {
  return survey_asked_s_ >= 0 &&
         (stage_ == Stage::kSurveyDropPoint || stage_ == Stage::kDescendToRelease || stage_ == Stage::kRelease);
}

// Settles at survey height over the default point, asks every step until the answer or the
// timeout, then flies over the decided point at survey height (the stretcher hangs ~3.5 m above
// the ground there: a diagonal descent toward a spot metres away would swing it low over whatever
// moved it) and descends.
void LifterSequence::RunSurveyDropPoint(const MissionInput& in, MissionOutput* out) {
  if (!in.payload_attached) {
    Enter(Stage::kTakeoffForPickup, in, out);
    return;
  }
  Hold(At(drop_xy_m_, SurveyZ()), kSlowSpeed_m_s, true, out);
  const bool at_height = std::abs(in.position_m.z() - SurveyZ()) <= kSurveyHeightTolerance_m;
  if (survey_decided_) {
    if (at_height && Arrived(in, drop_xy_m_)) Enter(Stage::kDescendToRelease, in, out);
    return;
  }
  if (survey_asked_s_ < 0) {
    if (!at_height || !Arrived(in, drop_xy_m_)) return;
    survey_asked_s_ = in.t_s;
    survey_yaw_rad_ = in.yaw_rad;  // the stretcher's length lies along it; held to the release
    out->setpoint.yaw_rad = survey_yaw_rad_;
  }
  if (in.drop_spot.has_value() && in.t_s > survey_asked_s_) {
    TakeDropSpotAnswer(in, *in.drop_spot, out);
  } else if (in.t_s - survey_asked_s_ >= config_.survey_timeout_s) {
    survey_decided_ = true;
    out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "drop_spot_unverified")
                                        .Add("victim", static_cast<std::int64_t>(victim_))
                                        .Add("reason", "no_depth")));
  } else {
    out->want_drop_spot = true;
    out->drop_spot_default_xy_m = drop_xy_m_;
    out->drop_spot_yaw_rad = survey_yaw_rad_;
    out->drop_spot_victim_xy_m = victim_xy_m_;
    return;
  }
  if (Arrived(in, drop_xy_m_)) Enter(Stage::kDescendToRelease, in, out);
}

void LifterSequence::TakeDropSpotAnswer(const MissionInput& in, const DropSpotAnswer& answer, MissionOutput* out) {
  survey_decided_ = true;
  if (!answer.found) {
    out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "drop_spot_none")
                                        .Add("victim", static_cast<std::int64_t>(victim_))
                                        .Add("x", drop_xy_m_.x(), 2)
                                        .Add("y", drop_xy_m_.y(), 2)));
    return;
  }
  const double moved_m = (answer.xy_m - drop_xy_m_).norm();
  drop_xy_m_ = answer.xy_m;
  out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "drop_spot_chosen")
                                      .Add("victim", static_cast<std::int64_t>(victim_))
                                      .Add("x", drop_xy_m_.x(), 2)
                                      .Add("y", drop_xy_m_.y(), 2)
                                      .Add("moved_m", moved_m, 2)
                                      .Add("slope_deg", answer.slope_deg, 1)
                                      .Add("default_ok", answer.default_ok)));
  out->setpoint.target_m = At(drop_xy_m_, SurveyZ());  // over the new point first
}

void LifterSequence::RunDescend(const MissionInput& in, const Vec2& xy_m, Stage next, MissionOutput* out) {
  const Vec3 target = At(xy_m, ReleaseZ());
  Hold(target, kSlowSpeed_m_s, true, out);
  if (Settled(in, target, /*release=*/true)) Enter(next, in, out);
}

bool LifterSequence::ReleasedAt(const MissionInput& in, const Vec2& xy_m, MissionOutput* out) {
  Hold(At(xy_m, ReleaseZ()), kSlowSpeed_m_s, true, out);
  if (in.payload_attached) {
    RequestPayload(in, PayloadAction::kRelease, 0.0, out);
    return false;
  }
  stretcher_xy_m_ = in.position_m.head<2>();  // it hung under us (release tolerance: not exactly at xy_m)
  return true;
}

void LifterSequence::RunRelease(const MissionInput& in, MissionOutput* out) {
  if (!ReleasedAt(in, drop_xy_m_, out)) return;
  out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "stretcher_released")
                                      .Add("victim", static_cast<std::int64_t>(victim_))
                                      .Add("x", drop_xy_m_.x(), 2)
                                      .Add("y", drop_xy_m_.y(), 2)));
  Enter(Stage::kWaitLoading, in, out);
}

void LifterSequence::RunWaitLoading(const MissionInput& in, MissionOutput* out) {
  Hold(At(stretcher_xy_m_, AttachZ()), kSlowSpeed_m_s, false, out);
  if (in.t_s - stage_start_s_ >= config_.loading_time_s) Enter(Stage::kAttachLoaded, in, out);
}

void LifterSequence::RunAttachLoaded(const MissionInput& in, MissionOutput* out) {
  const Vec3 target = At(stretcher_xy_m_, AttachZ());
  Hold(target, kSlowSpeed_m_s, false, out);
  if (in.payload_attached) {
    out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "evacuee_loaded")
                                        .Add("victim", static_cast<std::int64_t>(victim_))
                                        .Add("mass_kg", config_.loaded_mass_kg, 1)));
    Enter(Stage::kClimbWithLoad, in, out);
  } else if (Settled(in, target)) {
    RequestPayload(in, PayloadAction::kAttach, config_.loaded_mass_kg, out);
  }
}

void LifterSequence::RunCarryHome(const MissionInput& in, MissionOutput* out) {
  if (!in.payload_attached && victim_ != 0) {
    Enter(Stage::kAttachLoaded, in, out);
    return;
  }
  Hold(At(HomeXy(), TransitZ()), victim_ != 0 ? config_.loaded_speed_m_s : config_.cruise_speed_m_s,
       in.payload_attached, out);
  if (Arrived(in, HomeXy())) {
    Enter(in.payload_attached ? Stage::kDescendToDrop : Stage::kMoveToLandingPoint, in, out);
  }
}

void LifterSequence::RunReleaseAtHome(const MissionInput& in, MissionOutput* out) {
  if (!ReleasedAt(in, HomeXy(), out)) return;
  if (victim_ != 0) {
    delivered_victim_ = victim_;
    last_proposal_s_ = in.t_s;
    out->proposals.push_back(raft::MarkRescued{victim_});
    out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "victim_delivered")
                                        .Add("victim", static_cast<std::int64_t>(victim_))));
    victim_ = 0;
  }
  Enter(config_.standby_after_delivery && !in.battery_low ? Stage::kStandby : Stage::kMoveToLandingPoint, in, out);
}

void LifterSequence::RunMoveToLandingPoint(const MissionInput& in, MissionOutput* out) {
  const Vec3& p = in.position_m;
  const Vec2 pad = HomeXy() + config_.land_offset_m;
  const double z = std::max(AttachZ() + kLandingPointAboveAttach_m, std::min(p.z(), TransitZ()));
  Hold(At(pad, z), config_.cruise_speed_m_s, false, out);
  if ((p.head<2>() - pad).norm() <= config_.position_tolerance_m &&
      in.velocity_m_s.norm() < kLandingPointSpeed_m_s) {
    Enter(Stage::kLanding, in, out);
  }
}

void LifterSequence::RunLanding(const MissionInput& in, MissionOutput* out) {
  const Vec2 pad = HomeXy() + config_.land_offset_m;
  out->setpoint.kind = SetpointKind::kLand;
  out->setpoint.target_m = At(pad, Ground());
  if (in.position_m.z() <= Ground() + config_.base_height_m + kOnGroundAboveBase_m &&
      in.velocity_m_s.norm() < kOnGroundSpeed_m_s) {
    Enter(Stage::kOnGround, in, out);
  }
}

}  // namespace swarmbox::swarm
