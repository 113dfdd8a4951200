#include "mission_sim.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace swarmbox::swarm::testing {
namespace {

std::string EventLine(const raft::MissionEvent& e, double t_s) {
  using Kind = raft::MissionEvent::Kind;
  LogEvent l(t_s, "raft", e.kind == Kind::kPhase ? "mission_state"
                          : e.kind == Kind::kVictimConfirmed ? "victim_confirmed"
                                                             : "victim_status");
  if (e.kind == Kind::kPhase) {
    l.Add("state", raft::PhaseName(e.phase));
  } else {
    l.Add("id", static_cast<std::int64_t>(e.victim.id)).Add("status", raft::VictimStatusName(e.victim.status));
  }
  return l.str();
}

}  // namespace

MissionSim::MissionSim(MissionSimConfig config)
    : config_(std::move(config)), rng_(config_.seed), false_alarm_fired_(config_.false_alarms_m.size(), false) {
  for (const SimDrone& d : config_.drones) {
    planners_.emplace_back(LeaderConfig{.name = d.name, .search_area = config_.area, .retry_s = 2.0,
                                        .start_timeout_s = 60.0, .handle_time_s = 20.0});
    heard_s_.push_back(0.0);
    heard_mode_.push_back("on_ground");
    heard_pos_.push_back(d.home_m.head<2>());
  }
  bool lifter_present = false;
  for (const SimDrone& d : config_.drones) lifter_present = lifter_present || d.role == Role::kLifter;
  FlockingParams fp;
  for (const SimDrone& d : config_.drones) {
    pos_.push_back(d.home_m + Vec3(0, 0, d.base_height_m));
    vel_.push_back(Vec3::Zero());
    yaw_.push_back(0.0);
    modes_.push_back("on_ground");
    out_.emplace_back();
    drop_spot_answers_.emplace_back();
    detections_.emplace_back();
    flock_.emplace_back(fp, Geofence::Centered(config_.geofence_m.x(), config_.geofence_m.y()));
    if (d.role == Role::kScout) {
      ScoutConfig c;
      c.name = d.name;
      c.home_m = d.home_m;
      c.base_height_m = d.base_height_m;
      c.lifter_present = lifter_present;
      c.orbit_time_s = 15.0;
      c.takeoff_delay_s = config_.takeoff_wave_s * TakeoffWave(d.home_m.head<2>(), 4.0);
      c.search_altitude_m = config_.scout_altitude_m;
      c.min_clearance_m = config_.scout_min_clearance_m;
      if (config_.agent_tuning) {  // as SarBrain::Start
        c.cruise_speed_m_s = 7.0;
        c.orbit_radius_m = 12.0;
        c.orbit_time_s = 20.0;
        c.keep_searching_during_rescue = true;
        c.return_when_swept = true;
        c.approach_height_m = 5.0;
        c.home_approach_m = 3.0;
        c.return_layer = TakeoffWave(d.home_m.head<2>(), 4.0);
      }
      behaviour_of_.push_back(static_cast<int>(scouts_.size()));
      scouts_.emplace_back(c);
    } else {
      LifterConfig c;
      c.name = d.name;
      c.home_m = d.home_m;
      c.base_height_m = d.base_height_m;
      c.loading_time_s = config_.loading_time_s;
      c.survey_drop_point = config_.lifter_survey_drop_point;
      behaviour_of_.push_back(static_cast<int>(lifters_.size()));
      lifters_.emplace_back(c);
      stretcher_xy_ = d.home_m.head<2>();
    }
  }
}

bool MissionSim::Killed(std::size_t drone) const {
  for (const MissionSimConfig::Outage& o : config_.outages) {
    if (o.killed && o.drone == config_.drones[drone].name && t_s_ >= o.from_s) return true;
  }
  return false;
}

bool MissionSim::Silent(std::size_t drone) const {
  for (const MissionSimConfig::Outage& o : config_.outages) {
    if (!o.killed && o.drone == config_.drones[drone].name && t_s_ >= o.from_s && t_s_ < o.until_s) return true;
  }
  return false;
}

std::string MissionSim::FirstLine(const std::string& event, const std::string& also) const {
  const std::string needle = "event=" + event;
  for (const std::string& l : log_) {
    const std::size_t at = l.find(needle);
    if (at == std::string::npos) continue;
    const std::size_t end = at + needle.size();
    if (end != l.size() && l[end] != ' ') continue;
    if (!also.empty() && l.find(also) == std::string::npos) continue;
    return l;
  }
  return "";
}

double MissionSim::FirstTime(const std::string& event, const std::string& also) const {
  const std::string l = FirstLine(event, also);
  if (l.rfind("t=", 0) != 0) return -1.0;
  return std::stod(l.substr(2));
}

bool MissionSim::Logged(const std::string& event) const {
  const std::string needle = "event=" + event;
  for (const std::string& l : log_) {
    if (l.find(needle + " ") != std::string::npos ||
        (l.size() >= needle.size() && l.compare(l.size() - needle.size(), needle.size(), needle) == 0)) {
      return true;
    }
  }
  return false;
}

void MissionSim::Step() {
  const double dt = config_.dt_s;
  t_s_ += dt;
  // The "committed log".
  std::stable_sort(pending_.begin(), pending_.end(),
                   [](const Pending& a, const Pending& b) { return a.due_s < b.due_s; });
  while (!pending_.empty() && pending_.front().due_s <= t_s_) {
    const raft::ApplyResult r = mission_.Apply(++index_, pending_.front().command);
    if (!r.accepted) ++rejected_;
    for (const raft::MissionEvent& e : r.events) log_.push_back(EventLine(e, t_s_));
    pending_.erase(pending_.begin());
  }
  // Fake camera at 5 Hz: victims inside 90% of a scout's footprint.
  const bool camera = t_s_ >= next_camera_s_;
  if (camera) next_camera_s_ += 0.2;
  std::normal_distribution<double> noise(0.0, config_.detection_sigma_m);
  const std::size_t n = config_.drones.size();
  for (std::size_t i = 0; i < n; ++i) {
    detections_[i].clear();
    const SimDrone& d = config_.drones[i];
    const double height = pos_[i].z() - d.home_m.z();
    if (!camera || d.role != Role::kScout || height < 5.0) continue;
    const CameraFootprint fp = GroundFootprint(height, 1.2, 320, 240);
    const auto in_view = [&](const Vec2& v) {
      const Vec2 w = v - pos_[i].head<2>();
      const double c = std::cos(yaw_[i]), s = std::sin(yaw_[i]);
      const Vec2 b(c * w.x() + s * w.y(), -s * w.x() + c * w.y());  // body x forward, y left
      return std::abs(b.x()) <= 0.45 * fp.along_m && std::abs(b.y()) <= 0.45 * fp.across_m;
    };
    const auto detect = [&](const Vec2& v, double confidence) {
      GroundDetection g;
      g.capture_time_s = t_s_;
      g.visible_time_s = t_s_ + 0.04;
      g.position_m = Vec3(v.x() + noise(rng_), v.y() + noise(rng_), 0.0);
      g.sigma_m = config_.detection_sigma_m;
      g.confidence = confidence;
      g.viewer_m = pos_[i];
      detections_[i].push_back(g);
    };
    for (const Vec2& v : config_.victims_m) {
      if (!in_view(v)) continue;
      if (config_.recall < 1.0 && std::uniform_real_distribution<double>(0.0, 1.0)(rng_) >= config_.recall) continue;
      detect(v, config_.victim_confidence);
    }
    for (std::size_t k = 0; k < config_.false_alarms_m.size(); ++k) {
      if (false_alarm_fired_[k] || !in_view(config_.false_alarms_m[k])) continue;
      false_alarm_fired_[k] = true;
      detect(config_.false_alarms_m[k], config_.false_alarm_confidence);
    }
  }
  // Behaviours.
  const double battery = std::max(0.0, config_.battery_fraction_at_start - config_.battery_drain_per_s * t_s_);
  for (std::size_t i = 0; i < n; ++i) {
    const SimDrone& d = config_.drones[i];
    if (Killed(i)) {  // companion computer gone: motors off, it drops, nothing more from it
      out_[i].setpoint = {};
      out_[i].setpoint.kind = SetpointKind::kIdle;
      pos_[i].z() = d.home_m.z() + d.base_height_m;
      continue;
    }
    if (!Silent(i)) heard_s_[i] = t_s_;
    MissionInput in;
    in.t_s = t_s_;
    in.mission = &mission_;
    in.position_m = pos_[i];
    in.velocity_m_s = vel_[i];
    in.yaw_rad = yaw_[i];
    in.battery_fraction = battery;
    in.battery_low = battery < 0.2;
    in.payload_attached = d.role == Role::kLifter && attached_;
    in.detections = detections_[i];
    in.drop_spot = std::exchange(drop_spot_answers_[i], std::nullopt);
    if (camera && config_.fake_depth && d.role == Role::kScout) in.obstacle_top_z_m = FakeDepth(i);
    MissionOutput& out = out_[i];
    if (d.role == Role::kScout) {
      scouts_[static_cast<std::size_t>(behaviour_of_[i])].Step(in, &out);
    } else {
      lifters_[static_cast<std::size_t>(behaviour_of_[i])].Step(in, &out);
    }
    modes_[i] = out.mode;
    if (out.want_drop_spot && config_.drop_spot_offset_m) {  // fake depth host: answers next step
      drop_spot_answers_[i] = DropSpotAnswer{.found = true, .xy_m = out.drop_spot_default_xy_m + *config_.drop_spot_offset_m,
                                             .slope_deg = 1.0, .height_m = d.home_m.z(), .default_ok = false};
    }
    if (!Silent(i)) {
      heard_mode_[i] = std::string(out.mode);
      heard_pos_[i] = pos_[i].head<2>();
    }
    for (const LogEvent& e : out.events) log_.push_back(e.str());
    if (!Silent(i)) {
      for (const raft::MissionCommand& c : out.proposals) pending_.push_back({t_s_ + config_.commit_delay_s, c});
    }
    // Fake world: payload commands with the physics server's sling geometry (x8_heavy).
    if (out.payload.action == PayloadAction::kAttach && !attached_) {
      const double hook_to_payload = (Vec3(pos_[i].x(), pos_[i].y(), pos_[i].z() - 0.4) -
                                      Vec3(stretcher_xy_.x(), stretcher_xy_.y(), d.home_m.z() + 0.125)).norm();
      if (std::abs(hook_to_payload - 4.0) <= 0.5) {
        attached_ = true;
        payload_mass_kg_ = out.payload.mass_kg;
        log_.push_back(LogEvent(t_s_, "world", "payload_attached").Add("mass_kg", payload_mass_kg_, 1).str());
      }
    } else if (out.payload.action == PayloadAction::kRelease && attached_) {
      attached_ = false;
      stretcher_xy_ = pos_[i].head<2>();
      log_.push_back(LogEvent(t_s_, "world", "payload_released").str());
    }
  }
  // Leader: the first drone alive and heard (Raft would elect one of those).
  std::size_t lead_i = n;
  for (std::size_t i = 0; i < n && lead_i == n; ++i) {
    if (!Killed(i) && !Silent(i)) lead_i = i;
  }
  if (lead_i != leader_index_ && lead_i < n) {
    leader_index_ = lead_i;
    log_.push_back(LogEvent(t_s_, config_.drones[lead_i].name, "leader_elected").Add("leader", config_.drones[lead_i].name).str());
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!Killed(i)) planners_[i].Track(t_s_, mission_);
  }
  if (lead_i < n) {
    std::vector<RosterEntry> roster;
    for (std::size_t i = 0; i < n; ++i) {
      RosterEntry r;
      r.name = config_.drones[i].name;
      r.role = config_.drones[i].role;
      r.mode = heard_mode_[i];
      r.age_s = i == lead_i ? 0.0 : t_s_ - heard_s_[i] + config_.state_age_s;
      r.position_m = heard_pos_[i];
      roster.push_back(std::move(r));
    }
    MissionOutput lead;
    planners_[lead_i].Step(t_s_, mission_, roster, &lead);
    for (const LogEvent& e : lead.events) log_.push_back(e.str());
    for (const raft::MissionCommand& c : lead.proposals) pending_.push_back({t_s_ + config_.commit_delay_s, c});
  }

  // Kinematics.
  const double alpha = 1.0 - std::exp(-dt / 0.3);
  for (std::size_t i = 0; i < n; ++i) {
    const SimDrone& d = config_.drones[i];
    const SetpointRequest& sp = out_[i].setpoint;
    const double ground = d.home_m.z() + d.base_height_m;
    Vec3 cmd = Vec3::Zero();
    const double vmax = sp.max_speed_m_s > 0 ? sp.max_speed_m_s : 5.0;
    switch (sp.kind) {
      case SetpointKind::kIdle:
        vel_[i].setZero();
        continue;
      case SetpointKind::kTakeoff:
        cmd = Vec3(0, 0, std::clamp(sp.target_m.z() - pos_[i].z(), -2.0, 2.0));
        break;
      case SetpointKind::kPosition: {
        Vec3 e = sp.target_m - pos_[i];
        Vec2 h = e.head<2>();
        if (h.norm() > vmax) h *= vmax / h.norm();
        cmd = Vec3(h.x(), h.y(), std::clamp(e.z(), -1.5, 1.5));
        break;
      }
      case SetpointKind::kFlock: {
        scratch_.clear();
        for (std::size_t j = 0; j < n; ++j) {
          if (j != i && pos_[j].z() > config_.drones[j].home_m.z() + 1.0) scratch_.push_back({pos_[j], vel_[j], 0.0});
        }
        cmd = flock_[i].Step({pos_[i], vel_[i], sp.target_m, scratch_}, dt).velocity_m_s;
        break;
      }
      case SetpointKind::kLand: {
        Vec2 h = sp.target_m.head<2>() - pos_[i].head<2>();
        if (h.norm() > 1.0) h = h.normalized();
        cmd = Vec3(h.x(), h.y(), -1.0);
        break;
      }
    }
    if (sp.kind != SetpointKind::kFlock) flock_[i].Reset(vel_[i]);
    vel_[i] += alpha * (cmd - vel_[i]);
    pos_[i] += dt * vel_[i];
    if (pos_[i].z() < ground) {
      pos_[i].z() = ground;
      vel_[i].z() = std::max(0.0, vel_[i].z());
      if (sp.kind == SetpointKind::kLand) vel_[i].setZero();
    }
    if (vel_[i].head<2>().norm() > 0.5) yaw_[i] = std::atan2(vel_[i].y(), vel_[i].x());
    if (d.role == Role::kLifter && attached_) stretcher_xy_ = pos_[i].head<2>();
    MeasureClearance(i);
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const double d = (pos_[i] - pos_[j]).norm();
      if (pos_[i].z() > 2.0 && pos_[j].z() > 2.0 && d < min_pair_m_) {
        min_pair_m_ = d;
        min_pair_where_ = "t=" + std::to_string(t_s_) + " " + config_.drones[i].name + "(" +
                          std::string(modes_[i]) + ") " + config_.drones[j].name + "(" +
                          std::string(modes_[j]) + ")";
      }
      if (out_[i].setpoint.kind == SetpointKind::kFlock && out_[j].setpoint.kind == SetpointKind::kFlock) {
        min_flock_pair_m_ = std::min(min_flock_pair_m_, d);
      }
    }
  }
}

std::optional<double> MissionSim::FakeDepth(std::size_t drone) const {
  const Vec3& p = pos_[drone];
  const double ground_z_m = config_.drones[drone].home_m.z();
  std::optional<double> top;
  if (p.z() - ground_z_m <= config_.fake_depth_range_m) top = ground_z_m;
  for (const MissionSimConfig::Obstacle& o : config_.obstacles) {
    const Vec2 nearest(std::clamp(p.x(), o.area.x_min_m, o.area.x_max_m),
                       std::clamp(p.y(), o.area.y_min_m, o.area.y_max_m));
    const bool near = (nearest - p.head<2>()).norm() <= config_.fake_depth_radius_m;
    if (!near || p.z() - o.top_z_m > config_.fake_depth_range_m) continue;
    top = std::max(top.value_or(o.top_z_m), o.top_z_m);
  }
  return top;
}

void MissionSim::MeasureClearance(std::size_t drone) {
  const SimDrone& d = config_.drones[drone];
  if (d.role != Role::kScout || pos_[drone].z() < d.home_m.z() + 2.0) return;
  const Vec2 p = pos_[drone].head<2>();
  const double e = config_.obstacle_edge_m;
  for (const MissionSimConfig::Obstacle& o : config_.obstacles) {
    if (!o.area.Contains(p)) continue;
    const double clearance_m = pos_[drone].z() - o.top_z_m;
    min_clearance_m_ = std::min(min_clearance_m_, clearance_m);
    const Rect inner{o.area.x_min_m + e, o.area.y_min_m + e, o.area.x_max_m - e, o.area.y_max_m - e};
    if (inner.Contains(p)) min_inner_clearance_m_ = std::min(min_inner_clearance_m_, clearance_m);
  }
}

}  // namespace swarmbox::swarm::testing
