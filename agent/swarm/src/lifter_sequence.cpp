#include "swarmbox/swarm/lifter_sequence.hpp"

#include <cmath>
#include <utility>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {

using raft::MissionPhase;
using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

std::string_view LifterSequence::StageName(Stage stage) {
  switch (stage) {
    case Stage::kOnGround: return "on_ground";
    case Stage::kTakeoffForPickup: return "takeoff_for_pickup";
    case Stage::kAttachEmpty: return "attach_empty";
    case Stage::kClimbToTransit: return "climb";
    case Stage::kTransitToVictim: return "transit_to_victim";
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
  const raft::MissionState& m = *in.mission;
  const Vec3& p = in.position_m;
  const Vec2 home_xy = config_.home_m.head<2>();

  // MarkRescued until it is committed (proposals can be lost with a leader change).
  if (delivered_victim_ != 0) {
    const raft::Victim* v = m.FindVictim(delivered_victim_);
    if (v == nullptr || v->status == raft::VictimStatus::kRescued) {
      delivered_victim_ = 0;
    } else if (in.t_s - last_proposal_s_ >= config_.proposal_retry_s) {
      last_proposal_s_ = in.t_s;
      out->proposals.push_back(raft::MarkRescued{delivered_victim_});
    }
  }

  // Battery low: abandon what is not loaded yet and go home.
  if (in.battery_low && !battery_low_reported_ && stage_ != Stage::kOnGround) {
    battery_low_reported_ = true;
    out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "battery_low")
                                        .Add("battery", in.battery_fraction, 3)
                                        .Add("distance_home_m", (p.head<2>() - home_xy).norm(), 1)));
    // Not loaded yet: abandon the rescue (the stretcher comes home if it still hangs below).
    // Loaded (kClimbWithLoad and later): already on the way home with the evacuee.
    const bool loaded = stage_ > Stage::kAttachLoaded ||
                        (stage_ == Stage::kAttachLoaded && in.payload_attached);
    if (!loaded) {
      out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "rescue_abandoned")
                                          .Add("victim", static_cast<std::int64_t>(victim_))
                                          .Add("reason", "battery_low")));
      victim_ = 0;
      Enter(in.payload_attached ? Stage::kCarryHome : Stage::kMoveToLandingPoint, in, out);
    }
  }

  // A transition re-runs the new stage at once, so the setpoint always belongs to out.mode.
  for (int pass = 0; pass < 4; ++pass) {
    const Stage before = stage_;
    RunStage(in, out);
    if (stage_ == before) break;
  }
  out->mode = StageName(stage_);
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
  const Vec2 home_xy = config_.home_m.head<2>();
  Vec2 toward_home = home_xy - victim_xy_m_;
  toward_home = toward_home.norm() > 1e-6 ? Vec2(toward_home.normalized()) : Vec2(1, 0);
  drop_xy_m_ = victim_xy_m_ + config_.stretcher_offset_m * toward_home;
  return true;
}

void LifterSequence::RunStage(const MissionInput& in, MissionOutput* out) {
  const raft::MissionState& m = *in.mission;
  const Vec3& p = in.position_m;
  const Vec2 home_xy = config_.home_m.head<2>();
  const double attach_z = Ground() + config_.AttachHeight();
  const double release_z = attach_z - config_.release_sink_m;
  const double transit_z = Ground() + config_.transit_altitude_m;
  const double cruise = config_.cruise_speed_m_s;
  const double slow = 0.5;  // vertical legs near the ground [m/s]
  SetpointRequest& sp = out->setpoint;
  sp = {};
  sp.yaw_rad = in.yaw_rad;
  sp.target_m = p;
  switch (stage_) {
    case Stage::kOnGround:
      sp.kind = SetpointKind::kIdle;
      if (TakeRescue(in)) Enter(Stage::kTakeoffForPickup, in, out);
      break;
    case Stage::kStandby: {
      Hold({stretcher_xy_m_.x(), stretcher_xy_m_.y(), attach_z}, slow, false, out);
      if (TakeRescue(in)) {  // over the stretcher already: settle, then hook it
        Enter(Stage::kTakeoffForPickup, in, out);
        break;
      }
      bool waiting = false;  // a confirmed victim nobody rescues yet
      for (const raft::Victim& v : m.victims()) waiting = waiting || v.status == raft::VictimStatus::kConfirmed;
      const bool over = m.phase() == MissionPhase::kReturn || m.phase() == MissionPhase::kComplete;
      if (!waiting || over || in.battery_low) Enter(Stage::kMoveToLandingPoint, in, out);
      break;
    }
    case Stage::kTakeoffForPickup: {
      const Vec3 pickup(stretcher_xy_m_.x(), stretcher_xy_m_.y(), attach_z);
      if (p.z() < Ground() + config_.base_height_m + 1.5) {
        sp.kind = SetpointKind::kTakeoff;
        sp.target_m = {p.x(), p.y(), attach_z};
      } else {
        Hold(pickup, slow, false, out);
      }
      if (Settled(in, pickup)) Enter(Stage::kAttachEmpty, in, out);
      break;
    }
    case Stage::kAttachEmpty:
      Hold({stretcher_xy_m_.x(), stretcher_xy_m_.y(), attach_z}, slow, false, out);
      if (in.payload_attached) {
        Enter(Stage::kClimbToTransit, in, out);
      } else {
        RequestPayload(in, PayloadAction::kAttach, config_.empty_stretcher_mass_kg, out);
      }
      break;
    case Stage::kClimbToTransit: {
      if (!in.payload_attached) {  // the load check found the hook empty: go back for it
        Enter(Stage::kTakeoffForPickup, in, out);
        break;
      }
      Hold({stretcher_xy_m_.x(), stretcher_xy_m_.y(), transit_z}, cruise, true, out);
      if (std::abs(p.z() - transit_z) <= 1.0) Enter(Stage::kTransitToVictim, in, out);
      break;
    }
    case Stage::kTransitToVictim:
      if (!in.payload_attached) {
        Enter(Stage::kTakeoffForPickup, in, out);
        break;
      }
      Hold({drop_xy_m_.x(), drop_xy_m_.y(), transit_z}, cruise, true, out);
      if ((p.head<2>() - drop_xy_m_).norm() <= config_.arrive_tolerance_m &&
          in.velocity_m_s.norm() < config_.arrive_speed_m_s) {
        Enter(Stage::kDescendToRelease, in, out);
      }
      break;
    case Stage::kDescendToRelease: {
      const Vec3 target(drop_xy_m_.x(), drop_xy_m_.y(), release_z);
      Hold(target, slow, true, out);
      if (Settled(in, target, /*release=*/true)) Enter(Stage::kRelease, in, out);
      break;
    }
    case Stage::kRelease:
      Hold({drop_xy_m_.x(), drop_xy_m_.y(), release_z}, slow, true, out);
      if (!in.payload_attached) {
        stretcher_xy_m_ = p.head<2>();  // it hung under us (release tolerance: not exactly at the drop point)
        out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "stretcher_released")
                                            .Add("victim", static_cast<std::int64_t>(victim_))
                                            .Add("x", drop_xy_m_.x(), 2)
                                            .Add("y", drop_xy_m_.y(), 2)));
        Enter(Stage::kWaitLoading, in, out);
      } else {
        RequestPayload(in, PayloadAction::kRelease, 0.0, out);
      }
      break;
    case Stage::kWaitLoading:
      Hold({stretcher_xy_m_.x(), stretcher_xy_m_.y(), attach_z}, slow, false, out);
      if (in.t_s - stage_start_s_ >= config_.loading_time_s) Enter(Stage::kAttachLoaded, in, out);
      break;
    case Stage::kAttachLoaded: {
      const Vec3 target(stretcher_xy_m_.x(), stretcher_xy_m_.y(), attach_z);
      Hold(target, slow, false, out);
      if (in.payload_attached) {
        out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "evacuee_loaded")
                                            .Add("victim", static_cast<std::int64_t>(victim_))
                                            .Add("mass_kg", config_.loaded_mass_kg, 1)));
        Enter(Stage::kClimbWithLoad, in, out);
      } else if (Settled(in, target)) {
        RequestPayload(in, PayloadAction::kAttach, config_.loaded_mass_kg, out);
      }
      break;
    }
    case Stage::kClimbWithLoad:
      if (!in.payload_attached) {  // the evacuee's stretcher stayed on the ground
        Enter(Stage::kAttachLoaded, in, out);
        break;
      }
      Hold({stretcher_xy_m_.x(), stretcher_xy_m_.y(), transit_z}, slow, true, out);
      if (std::abs(p.z() - transit_z) <= 1.0) Enter(Stage::kCarryHome, in, out);
      break;
    case Stage::kCarryHome:
      if (!in.payload_attached && victim_ != 0) {
        Enter(Stage::kAttachLoaded, in, out);
        break;
      }
      Hold({home_xy.x(), home_xy.y(), transit_z}, victim_ != 0 ? config_.loaded_speed_m_s : cruise,
           in.payload_attached, out);
      if ((p.head<2>() - home_xy).norm() <= config_.arrive_tolerance_m &&
          in.velocity_m_s.norm() < config_.arrive_speed_m_s) {
        Enter(in.payload_attached ? Stage::kDescendToDrop : Stage::kMoveToLandingPoint, in, out);
      }
      break;
    case Stage::kDescendToDrop: {
      const Vec3 target(home_xy.x(), home_xy.y(), release_z);
      Hold(target, slow, true, out);
      if (Settled(in, target, /*release=*/true)) Enter(Stage::kReleaseAtHome, in, out);
      break;
    }
    case Stage::kReleaseAtHome:
      Hold({home_xy.x(), home_xy.y(), release_z}, slow, true, out);
      if (!in.payload_attached) {
        stretcher_xy_m_ = p.head<2>();
        if (victim_ != 0) {
          delivered_victim_ = victim_;
          last_proposal_s_ = in.t_s;
          out->proposals.push_back(raft::MarkRescued{victim_});
          out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "victim_delivered")
                                              .Add("victim", static_cast<std::int64_t>(victim_))));
          victim_ = 0;
        }
        Enter(config_.standby_after_delivery && !in.battery_low ? Stage::kStandby : Stage::kMoveToLandingPoint, in, out);
      } else {
        RequestPayload(in, PayloadAction::kRelease, 0.0, out);
      }
      break;
    case Stage::kMoveToLandingPoint: {
      const Vec2 pad = home_xy + config_.land_offset_m;
      const double z = std::max(attach_z + 1.0, std::min(p.z(), transit_z));
      Hold({pad.x(), pad.y(), z}, cruise, false, out);
      if ((p.head<2>() - pad).norm() <= config_.position_tolerance_m && in.velocity_m_s.norm() < 0.5) {
        Enter(Stage::kLanding, in, out);
      }
      break;
    }
    case Stage::kLanding: {
      const Vec2 pad = home_xy + config_.land_offset_m;
      sp.kind = SetpointKind::kLand;
      sp.target_m = {pad.x(), pad.y(), Ground()};
      if (p.z() <= Ground() + config_.base_height_m + 0.15 && in.velocity_m_s.norm() < 0.3) {
        Enter(Stage::kOnGround, in, out);
      }
      break;
    }
  }
}


}  // namespace swarmbox::swarm
