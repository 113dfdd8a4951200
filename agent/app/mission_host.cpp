#include "mission_host.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::agent {
namespace {

using flight::Setpoint;
using flight::Vec3;
using swarm::Role;
using swarm::SetpointKind;

constexpr std::size_t kHistory = 128;  // control steps of estimates kept (0.5 s at 250 Hz)

bool OnGround(flight::FlightMode m) {
  return m == flight::FlightMode::kInit || m == flight::FlightMode::kIdle || m == flight::FlightMode::kLanded;
}

Status ReadCamera(const yaml::Node& cam, CameraSpec* c) {
  if (!cam.is_mapping()) return Error(ErrorCode::kInvalidArgument, "camera: expected a mapping", cam.Where());
  auto num = [&](std::string_view key, double* out) -> Status {
    const yaml::Node* n = cam.Find(key);
    if (n == nullptr) return Ok{};
    auto v = n->AsDouble();
    if (!v) return v.error();
    if (!(*v > 0)) return Error(ErrorCode::kInvalidArgument, "camera: " + std::string(key) + " must be > 0", n->Where());
    *out = *v;
    return Ok{};
  };
  double w = c->width_px, h = c->height_px;
  SWARMBOX_TRY(num("width_px", &w));
  SWARMBOX_TRY(num("height_px", &h));
  SWARMBOX_TRY(num("hfov_rad", &c->hfov_rad));
  SWARMBOX_TRY(num("rate_hz", &c->rate_hz));
  if (!(c->hfov_rad < M_PI)) return Error(ErrorCode::kInvalidArgument, "camera: hfov_rad must be < pi", cam.Where());
  c->width_px = static_cast<int>(w);
  c->height_px = static_cast<int>(h);
  if (const yaml::Node* off = cam.Find("offset_m")) {
    std::array<double, 3> a{};
    SWARMBOX_TRY(yaml::Decode(*off, &a));
    c->offset_m = Vec3(a[0], a[1], a[2]);
  }
  return Ok{};
}

}  // namespace

Result<CameraSpec> LoadCameraSpec(const std::string& airframe_path) {
  auto doc = yaml::ParseFile(airframe_path);
  if (!doc) return doc.error();
  const yaml::Node* cam = doc->is_mapping() ? doc->Find("camera") : nullptr;
  if (cam == nullptr) return Error(ErrorCode::kInvalidArgument, "airframe has no camera mapping", doc->Where());
  CameraSpec c;
  SWARMBOX_TRY(ReadCamera(*cam, &c));
  return c;
}

Result<GroundPayload> LoadGroundPayload(const std::string& airframe_path, const std::string& payload) {
  auto doc = yaml::ParseFile(airframe_path);
  if (!doc) return doc.error();
  if (!doc->is_mapping()) return Error(ErrorCode::kInvalidArgument, "airframe: expected a mapping", doc->Where());
  const yaml::Node* collision = doc->Find("collision");
  const yaml::Node* box = collision != nullptr && collision->is_mapping() ? collision->Find("box_m") : nullptr;
  if (box == nullptr) return Error(ErrorCode::kInvalidArgument, "airframe has no collision.box_m", doc->Where());
  std::array<double, 3> box_m{};
  SWARMBOX_TRY(yaml::Decode(*box, &box_m));
  const yaml::Node* list = doc->Find("payloads");
  if (list != nullptr && list->is_sequence()) {
    for (const yaml::Node& p : list->items()) {
      const yaml::Node* name = p.is_mapping() ? p.Find("name") : nullptr;
      if (name == nullptr || name->scalar() != payload) continue;
      const yaml::Node* size = p.Find("size_m");
      if (size == nullptr) return Error(ErrorCode::kInvalidArgument, "payload " + payload + " has no size_m", p.Where());
      std::array<double, 3> size_m{};
      SWARMBOX_TRY(yaml::Decode(*size, &size_m));
      GroundPayload g;
      g.offset_m = Eigen::Vector2d(0.0, -(box_m[1] / 2 + size_m[1] / 2 + 0.5));
      g.half_height_m = size_m[2] / 2;
      return g;
    }
  }
  return Error(ErrorCode::kInvalidArgument, "airframe has no payload '" + payload + "'", doc->Where());
}

std::string EncodeMissionMode(Role role, std::string_view mode) {
  return std::string(swarm::RoleName(role)) + "/" + std::string(mode);
}

bool DecodeMissionMode(std::string_view text, Role* role, std::string* mode) {
  const std::size_t slash = text.find('/');
  if (slash == std::string_view::npos || slash + 1 >= text.size()) return false;
  const std::string_view r = text.substr(0, slash);
  if (r == "scout") {
    *role = Role::kScout;
  } else if (r == "lifter") {
    *role = Role::kLifter;
  } else {
    return false;
  }
  *mode = std::string(text.substr(slash + 1));
  return true;
}

void MissionHostOutput::Clear() {
  command.reset();
  payload = {};
  proposals.clear();
  events.clear();
  detections.clear();
  mission_tick = false;
}

Result<std::unique_ptr<MissionHost>> MissionHost::Create(const MissionHostConfig& c) {
  if (c.name.empty()) return Error(ErrorCode::kInvalidArgument, "mission: no drone name");
  if (std::find(c.members.begin(), c.members.end(), c.name) == c.members.end()) {
    return Error(ErrorCode::kInvalidArgument, "mission: --members does not include '" + c.name + "'");
  }
  if (!(c.inference_latency_s >= 0)) return Error(ErrorCode::kInvalidArgument, "mission: inference latency must be >= 0");
  if (!(c.geofence_size_x_m > 2 * c.tuning.search_margin_m) || !(c.geofence_size_y_m > 2 * c.tuning.search_margin_m)) {
    return Error(ErrorCode::kInvalidArgument, "mission: the world's geofence is too small to search");
  }
  auto spec = swarm::BatterySpecFor(c.airframe);
  if (!spec) return spec.error().Context("mission battery model");
  return std::unique_ptr<MissionHost>(new MissionHost(c, swarm::BatteryModel(*spec)));
}

namespace {

swarm::FlockingParams FlockParams(const MissionTuning& t) {
  swarm::FlockingParams p;
  p.v_flock_m_s = t.scout_cruise_m_s;
  p.v_max_m_s = t.scout_cruise_m_s;
  return p;
}

swarm::PerceptionParams PerceptionFor(double latency_s) {
  swarm::PerceptionParams p;
  p.latency_s = latency_s;
  return p;
}

}  // namespace

MissionHost::MissionHost(const MissionHostConfig& config, swarm::BatteryModel battery)
    : config_(config),
      role_(config.payload.empty() ? Role::kScout : Role::kLifter),
      battery_(std::move(battery)),
      perception_(PerceptionFor(config.inference_latency_s)),
      flock_(FlockParams(config.tuning), swarm::Geofence::Centered(config.geofence_size_x_m, config.geofence_size_y_m)),
      mode_(EncodeMissionMode(role_, "on_ground")),
      history_(kHistory) {
  neighbours_.reserve(config_.members.size());
  out_.proposals.reserve(8);
  out_.events.reserve(16);
}

void MissionHost::RecordEstimate(double t_s, const flight::StateEstimate& est) {
  history_[history_next_] = {t_s, est.pos_m, est.att, est.rate_radps};
  history_next_ = (history_next_ + 1) % history_.size();
}

void MissionHost::OnCameraFrame(const cv::Mat& bgr, const swarm::PinholeIntrinsics& k, double capture_t_s) {
  if (role_ != Role::kScout) return;
  const Estimate* best = nullptr;
  for (const Estimate& e : history_) {
    if (e.t_s < 0) continue;
    if (best == nullptr || std::abs(e.t_s - capture_t_s) < std::abs(best->t_s - capture_t_s)) best = &e;
  }
  // The estimate of the capture step (or the nearest one within a step or two of it).
  if (best == nullptr || std::abs(best->t_s - capture_t_s) > 0.02) return;
  // Geolocation needs a steady camera: a tilted or turning drone multiplies attitude errors.
  const Vec3 up = best->att * Vec3::UnitZ();
  if (std::acos(std::clamp(up.z(), -1.0, 1.0)) > config_.tuning.max_tilt_for_perception_rad) return;
  if (best->rate_radps.norm() > config_.tuning.max_rate_for_perception_rad_s) return;
  const swarm::OpticalPose pose = swarm::OpticalPoseFromBody(best->pos_m, best->att, config_.camera.offset_m);
  (void)perception_.ProcessFrame(bgr, k, pose, capture_t_s);
}

void MissionHost::OnPeerState(const PeerState& peer) {
  if (peer.name == config_.name) return;
  if (std::find(config_.members.begin(), config_.members.end(), peer.name) == config_.members.end()) return;
  PeerState& p = peers_[peer.name];
  if (p.name.empty() || peer.sim_time_s >= p.sim_time_s) p = peer;
}

void MissionHost::Roster(double t_s, double wall_s, const flight::Vec3& own_position_m,
                         std::vector<swarm::RosterEntry>* out) const {
  out->clear();
  swarm::RosterEntry own;
  own.name = config_.name;
  own.position_m = own_position_m.head<2>();
  own.wall_age_s = 0.0;
  if (DecodeMissionMode(mode_, &own.role, &own.mode)) out->push_back(std::move(own));
  for (const auto& [name, p] : peers_) {
    swarm::RosterEntry e;
    e.name = name;
    // Age on the shared simulated clock (lockstep): see leader_planner.hpp for the timeout.
    e.age_s = std::max(0.0, t_s - p.sim_time_s);
    // And on the wall clock since it was received (infinite without wall times: the simulated
    // age alone decides), so that a radio delay at rtf 0 is not taken for silence.
    const double wall_age_s = wall_s - p.received_wall_s;
    if (std::isfinite(wall_age_s)) e.wall_age_s = std::max(0.0, wall_age_s);
    e.position_m = p.position_m.head<2>();
    if (DecodeMissionMode(p.mode, &e.role, &e.mode)) out->push_back(std::move(e));
  }
}

void MissionHost::Start(const MissionHostInput& in) {
  const flight::StateEstimate& est = *in.estimate;
  if (!est.valid || in.flight_mode == flight::FlightMode::kInit) return;
  // Wait (up to 10 s) until every member was heard, so roles are known (lifter present or not).
  std::size_t heard = 0;
  bool lifter_present = role_ == Role::kLifter;
  for (const auto& [name, p] : peers_) {
    Role r;
    std::string m;
    if (DecodeMissionMode(p.mode, &r, &m)) {
      ++heard;
      lifter_present = lifter_present || r == Role::kLifter;
    }
  }
  if (heard + 1 < config_.members.size() && in.t_s < 10.0) return;
  home_m_ = config_.has_home ? config_.home_m : Vec3(est.pos_m - Vec3(0, 0, config_.base_height_m));
  const MissionTuning& t = config_.tuning;
  if (role_ == Role::kScout) {
    swarm::ScoutConfig s;
    s.name = config_.name;
    s.home_m = home_m_;
    s.base_height_m = config_.base_height_m;
    s.search_altitude_m = t.scout_altitude_m;
    s.takeoff_delay_s = in.t_s + 2.0;  // the estimator settles on the ground (as the plan's preflight)
    s.hfov_rad = config_.camera.hfov_rad;
    s.width_px = config_.camera.width_px;
    s.height_px = config_.camera.height_px;
    s.cruise_speed_m_s = t.scout_cruise_m_s;
    s.orbit_radius_m = t.scout_orbit_radius_m;
    s.lifter_present = lifter_present;
    s.dedupe_radius_m = t.sighting_dedupe_m;
    s.keep_searching_during_rescue = true;  // the lifter does the rescue; scouts finish the search
    s.return_when_swept = true;             // nothing left to see: land, do not loiter
    s.approach_height_m = 5.0;              // descend at vel_max_down, land the last 5 m
    s.orbit_time_s = t.scout_orbit_time_s;
    // After a restart, sighting sequence numbers continue above any used before (sim ms).
    s.first_sighting_seq = static_cast<std::uint64_t>(in.t_s * 1000.0) + 1;
    scout_.emplace(std::move(s));
  } else {
    swarm::LifterConfig l;
    l.name = config_.name;
    l.home_m = home_m_;
    l.base_height_m = config_.base_height_m;
    l.transit_altitude_m = t.lifter_transit_altitude_m;
    l.hook_below_body_m = -config_.payload_hook_m.z();
    l.sling_length_m = config_.payload_sling_length_m;
    l.payload_half_height_m = config_.payload_half_height_m;
    l.loading_time_s = t.lifter_loading_time_s;
    l.stretcher_start_offset_m = config_.payload_offset_m;
    l.standby_after_delivery = true;
    l.release_sink_m = -0.3;  // let go 0.3 m above the ground: no drag on a grounded stretcher
    // Hooking needs the hook within 4 +- 0.5 m of the stretcher's centre: 1 m sideways at 4 m
    // below changes that distance by 0.12 m, so the horizontal tolerance can be 1 m.
    l.position_tolerance_m = 1.0;
    l.settle_speed_m_s = 0.5;
    lifter_.emplace(std::move(l));
  }
  swarm::LeaderConfig lc;
  lc.name = config_.name;
  const double m = t.search_margin_m;
  lc.search_area = {-config_.geofence_size_x_m / 2 + m, -config_.geofence_size_y_m / 2 + m,
                    config_.geofence_size_x_m / 2 - m, config_.geofence_size_y_m / 2 - m};
  lc.retry_s = 2.0;
  lc.start_timeout_s = t.leader_start_timeout_s;
  lc.member_timeout_s = t.member_timeout_s;
  lc.member_min_wall_s = t.member_min_wall_s;
  lc.assignment_settle_s = t.assignment_settle_s;
  leader_.emplace(std::move(lc));
  out_.events.push_back(std::move(LogEvent(in.t_s, config_.name, "mission_start")
                                      .Add("role", swarm::RoleName(role_))
                                      .Add("home_x", home_m_.x(), 2)
                                      .Add("home_y", home_m_.y(), 2)
                                      .Add("lifter_present", lifter_present)));
}

const MissionHostOutput& MissionHost::Step(const MissionHostInput& in) {
  out_.Clear();
  const flight::StateEstimate& est = *in.estimate;
  battery_.Step(in.dt_s, est.vel_mps, payload_mass_kg(), !OnGround(in.flight_mode));
  const std::size_t before = visible_.size();
  perception_.PopVisible(in.t_s, &visible_);
  out_.detections.assign(visible_.begin() + static_cast<std::ptrdiff_t>(before), visible_.end());
  if (!scout_ && !lifter_) Start(in);
  if (!scout_ && !lifter_) return out_;
  if (in.t_s >= next_tick_s_) {
    next_tick_s_ = in.t_s + config_.tuning.mission_dt_s;
    if (role_ == Role::kLifter) CheckLoad(in);
    RunBehaviour(in);
  }
  if (in.mission->phase() == raft::MissionPhase::kComplete && !complete_logged_) {
    complete_logged_ = true;
    std::int64_t rescued = 0;
    for (const raft::Victim& v : in.mission->victims()) rescued += v.status == raft::VictimStatus::kRescued ? 1 : 0;
    out_.events.push_back(std::move(LogEvent(in.t_s, config_.name, "mission_complete")
                                        .Add("victims", static_cast<std::int64_t>(in.mission->victims().size()))
                                        .Add("rescued", rescued)));
  }
  return out_;
}

void MissionHost::RunBehaviour(const MissionHostInput& in) {
  const flight::StateEstimate& est = *in.estimate;
  out_.mission_tick = true;
  swarm::MissionInput mi;
  mi.t_s = in.t_s;
  mi.mission = in.mission;
  mi.position_m = est.pos_m;
  mi.velocity_m_s = est.vel_mps;
  mi.yaw_rad = flight::YawOf(est.att);
  mi.battery_fraction = battery_.fraction();
  const double to_home = (est.pos_m.head<2>() - home_m_.head<2>()).norm();
  mi.battery_low = battery_.IsLow(to_home, std::max(0.0, est.pos_m.z() - home_m_.z()), payload_mass_kg());
  mi.payload_attached = payload_attached_;
  mi.detections = visible_;
  if (scout_) {
    scout_->Step(mi, &behaviour_out_);
  } else {
    lifter_->Step(mi, &behaviour_out_);
  }
  visible_.clear();
  mode_ = EncodeMissionMode(role_, behaviour_out_.mode);
  for (raft::MissionCommand& c : behaviour_out_.proposals) out_.proposals.push_back(std::move(c));
  for (LogEvent& e : behaviour_out_.events) out_.events.push_back(std::move(e));
  if (behaviour_out_.payload.action != swarm::PayloadAction::kNone) Apply(behaviour_out_.payload);
  Drive(in, behaviour_out_.setpoint);

  leader_->Track(in.t_s, *in.mission, in.wall_s);  // every drone: a new leader knows when sectors changed
  if (in.is_leader) {
    std::vector<swarm::RosterEntry> roster;
    Roster(in.t_s, in.wall_s, est.pos_m, &roster);
    const bool everyone = roster.size() == config_.members.size();
    if (everyone || in.mission->phase() != raft::MissionPhase::kIdle || in.t_s >= config_.tuning.leader_start_timeout_s) {
      swarm::MissionOutput lead;
      leader_->Step(in.t_s, *in.mission, roster, &lead, in.wall_s);
      for (raft::MissionCommand& c : lead.proposals) out_.proposals.push_back(std::move(c));
      for (LogEvent& e : lead.events) {
        // Every drone logs mission_complete itself when it applies COMPLETE (Step()).
        if (e.str().find(" event=mission_complete") == std::string::npos) out_.events.push_back(std::move(e));
      }
    }
  }
}

void MissionHost::Apply(const swarm::PayloadRequest& p) {
  // The world command drives the simulated hook: the agent takes the hook's state to be the last
  // command it sent (a refused command shows as event=world_command_rejected in the physics log;
  // the lifter only asks once settled within the hook's reach).
  out_.payload = p;
  if (p.action == swarm::PayloadAction::kAttach) {
    payload_attached_ = true;
    payload_mass_kg_ = p.mass_kg;
    attach_t_s_ = next_tick_s_ - config_.tuning.mission_dt_s;
  } else if (p.action == swarm::PayloadAction::kRelease) {
    payload_attached_ = false;
    attach_t_s_ = -1.0;
  }
}

void MissionHost::CheckLoad(const MissionHostInput& in) {
  if (attach_t_s_ < 0 || !payload_attached_) return;
  const MissionTuning& t = config_.tuning;
  const double hook_height = -config_.payload_hook_m.z() + config_.payload_sling_length_m + config_.payload_half_height_m;
  const double height = in.estimate->pos_m.z() - home_m_.z();
  if (in.t_s - attach_t_s_ < t.load_check_delay_s || height < hook_height + t.load_check_climb_m) return;
  const double load = in.mass_estimate_kg - config_.vehicle_mass_kg;
  const bool ok = load >= t.load_check_fraction * payload_mass_kg_;
  out_.events.push_back(std::move(LogEvent(in.t_s, config_.name, ok ? "payload_confirmed" : "payload_missing")
                                      .Add("expected_kg", payload_mass_kg_, 1)
                                      .Add("estimated_kg", load, 1)));
  attach_t_s_ = -1.0;
  if (!ok) payload_attached_ = false;  // the world refused the hook: the lifter goes back for it
}

void MissionHost::Drive(const MissionHostInput& in, const swarm::SetpointRequest& sp) {
  const flight::StateEstimate& est = *in.estimate;
  const bool on_ground = OnGround(in.flight_mode);
  const bool changed = sp.kind != sent_kind_;
  switch (sp.kind) {
    case SetpointKind::kIdle:
      break;
    case SetpointKind::kTakeoff: {
      // A short flight-stack take-off, then the climb in position mode (faster: vel_max_up).
      const double height = sp.target_m.z() - est.pos_m.z();
      if (on_ground) {
        if (changed || in.flight_mode != flight::FlightMode::kTakeoff) {
          out_.command = Setpoint::Takeoff(std::clamp(height, 0.5, config_.tuning.scout_takeoff_step_m));
          climb_sent_ = false;
        }
      } else if (!climb_sent_ && (in.hover_event || in.flight_mode == flight::FlightMode::kHold)) {
        out_.command = Setpoint::Position(sp.target_m, std::nan(""));
        climb_sent_ = true;
      }
      break;
    }
    case SetpointKind::kPosition:
      if (on_ground) break;
      if (changed || (sp.target_m - sent_target_m_).norm() > 0.05) {
        out_.command = Setpoint::Position(sp.target_m, sp.yaw_rad);
        sent_target_m_ = sp.target_m;
      }
      break;
    case SetpointKind::kFlock: {
      if (on_ground) break;
      neighbours_.clear();
      for (const auto& [name, p] : peers_) {
        const double age = std::max(0.0, in.t_s - p.sim_time_s);
        if (p.position_m.z() < home_m_.z() + 1.5) continue;  // on the ground: not in the way
        neighbours_.push_back({p.position_m, p.velocity_m_s, age});
      }
      if (changed) flock_.Reset(est.vel_mps);
      swarm::FlockingInput fi;
      fi.position_m = est.pos_m;
      fi.velocity_m_s = est.vel_mps;
      fi.goal_m = sp.target_m;
      fi.neighbours = neighbours_;
      const swarm::FlockingOutput f = flock_.Step(fi, config_.tuning.mission_dt_s);
      out_.command = Setpoint::Velocity(f.velocity_m_s, sp.yaw_rad);
      break;
    }
    case SetpointKind::kLand:
      if (!on_ground && (changed || in.flight_mode != flight::FlightMode::kLand)) out_.command = Setpoint::Land();
      break;
  }
  if (sp.kind != SetpointKind::kPosition) sent_target_m_ = Vec3::Constant(1e9);
  sent_kind_ = sp.kind;
}

}  // namespace swarmbox::agent
