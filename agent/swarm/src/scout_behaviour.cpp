#include "swarmbox/swarm/scout_behaviour.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {
namespace {

using raft::MissionPhase;

constexpr double kTakeoffDoneBelowAltitude_m = 1.0;  // the climb ends this close to search altitude
constexpr double kOnGroundAboveBase_m = 0.15;  // touched down: body this close to base height
constexpr double kOnGroundSpeed_m_s = 0.3;
// A raised altitude is logged again (event=clearance_climb) when a taller obstacle raises it by
// this much: SGBM's error on a crown 6-10 m below is 0.3-0.8 m, so smaller steps are its noise.
constexpr double kClimbLogStep_m = 1.0;

bool Active(MissionPhase p) {
  return p == MissionPhase::kSearch || p == MissionPhase::kConverge || p == MissionPhase::kRescue;
}
bool Over(MissionPhase p) { return p == MissionPhase::kReturn || p == MissionPhase::kComplete; }

}  // namespace

int TakeoffWave(const Eigen::Vector2d& home_xy_m, double grid_m) {
  SWARMBOX_CHECK(grid_m > 0);
  const auto parity = [&](double v) {
    const auto i = static_cast<long long>(std::llround(v / grid_m));
    return static_cast<int>(((i % 2) + 2) % 2);
  };
  return parity(home_xy_m.x()) + 2 * parity(home_xy_m.y());
}

std::string_view RoleName(Role role) { return role == Role::kScout ? "scout" : "lifter"; }

std::string_view ScoutBehaviour::StageName(Stage stage) {
  switch (stage) {
    case Stage::kOnGround: return "on_ground";
    case Stage::kTakingOff: return "taking_off";
    case Stage::kAwaitingSector: return "awaiting_sector";
    case Stage::kSearching: return "searching";
    case Stage::kSwept: return "swept";
    case Stage::kOrbiting: return "orbiting";
    case Stage::kReturning: return "returning";
    case Stage::kLanding: return "landing";
    case Stage::kLanded: return "landed";
    case Stage::kRevisiting: return "revisiting";
  }
  return "?";
}

ScoutBehaviour::ScoutBehaviour(ScoutConfig config)
    : config_(std::move(config)),
      footprint_(GroundFootprint(config_.search_altitude_m, config_.hfov_rad, config_.width_px,
                                 config_.height_px)),
      next_seq_(config_.first_sighting_seq) {
  SWARMBOX_CHECK(!config_.name.empty());
  SWARMBOX_CHECK(config_.first_sighting_seq > 0);
  SWARMBOX_CHECK(config_.orbit_points >= 3 && config_.orbit_radius_m > 0);
  SWARMBOX_CHECK(config_.min_clearance_m >= 0 && config_.clearance_hold_s >= 0);
}

void ScoutBehaviour::Enter(Stage stage, const MissionInput& in, MissionOutput* out) {
  if (stage == stage_) return;
  // Taken off a lane (a revisit, an orbit): the search comes back to where it left the lane, the
  // point on the lane nearest the drone, and flies the rest of it from there; the first such point
  // stays until reached (another revisit on the way back does not move it on).
  if (stage_ == Stage::kSearching && has_plan_ && lane_index_ % 2 == 1 && lane_index_ < lanes_.size() &&
      !rejoin_m_) {
    const Eigen::Vector2d a = lanes_[lane_index_ - 1].position_m.head<2>();
    const Eigen::Vector2d b = lanes_[lane_index_].position_m.head<2>();
    const double length2 = (b - a).squaredNorm();
    const double along =
        length2 > 0 ? std::clamp((in.position_m.head<2>() - a).dot(b - a) / length2, 0.0, 1.0) : 1.0;
    rejoin_m_ = a + along * (b - a);
  }
  stage_ = stage;
  LogEvent e(in.t_s, config_.name, "mission_stage");
  e.Add("role", "scout").Add("stage", StageName(stage));
  if (stage == Stage::kSearching && has_plan_) e.Add("lane", static_cast<std::int64_t>(lane_index_ / 2));
  if (stage == Stage::kSearching && rejoin_m_)
    e.Add("rejoin_x", rejoin_m_->x(), 2).Add("rejoin_y", rejoin_m_->y(), 2);
  if (stage == Stage::kOrbiting) e.Add("victim", static_cast<std::int64_t>(orbit_victim_));
  if (stage == Stage::kRevisiting) e.Add("candidate", static_cast<std::int64_t>(revisit_id_));
  out->events.push_back(std::move(e));
}

void ScoutBehaviour::PlanSector(const raft::Sector& sector, const Eigen::Vector3d& position_m) {
  planned_sector_ = sector;
  has_plan_ = true;
  lanes_ = LawnmowerWaypoints(AsRect(sector), SweepSpacing(footprint_, config_.overlap), Altitude(),
                              footprint_, position_m.head<2>());
  lane_index_ = 0;
  rejoin_m_.reset();
}

const raft::Sector* ScoutBehaviour::NextSector(const raft::MissionState& m) const {
  for (const raft::Sector& s : m.sectors()) {
    if (s.drone == config_.name && std::find(swept_.begin(), swept_.end(), s) == swept_.end()) return &s;
  }
  return nullptr;
}

const raft::Victim* ScoutBehaviour::OrbitTarget(const MissionInput& in) const {
  const raft::MissionState& m = *in.mission;
  if (m.phase() != MissionPhase::kConverge && m.phase() != MissionPhase::kRescue) return nullptr;
  const raft::Victim* v = m.FindVictim(m.target_victim());
  if (v == nullptr || v->status == raft::VictimStatus::kRescued) return nullptr;
  if (handled_.count(v->id) != 0) return nullptr;
  return v;
}

namespace {

// A sight at p is of candidate c when the mission state will file it there: a look-alike a few
// metres off is another candidate's view, and c's revisit still waits for its answer (counting it
// as one left the scout hovering for the revisit's whole timeout with nothing reported:
// rubble20-a-r18 on 2026-11-29, a person 6 m from a backpack).
bool OfCandidate(const raft::MissionState& m, const raft::Candidate* c, const Eigen::Vector2d& p) {
  if (c == nullptr) return false;
  const raft::Candidate* filed = m.CandidateAt(p.x(), p.y());
  return filed != nullptr && filed->id == c->id;
}

}  // namespace

void ScoutBehaviour::ReportSightings(const MissionInput& in, MissionOutput* out) {
  const raft::MissionState& m = *in.mission;
  const raft::Candidate* revisit = stage_ == Stage::kRevisiting ? m.FindCandidate(revisit_id_) : nullptr;
  const double look_z = LookAltitude();
  for (const GroundDetection& d : in.detections) {
    if (d.confidence < config_.min_report_confidence) continue;
    const Eigen::Vector2d p = d.position_m.head<2>();
    if (!config_.sighting_area.Contains(p)) continue;  // beyond the geofence: out of reach
    bool known = false;
    for (const raft::Victim& v : m.victims()) {
      known = known || (Eigen::Vector2d(v.x_m, v.y_m) - p).norm() <= config_.dedupe_radius_m;
    }
    if (known) continue;
    // The first sight of the candidate on a revisit always goes out: it is the revisit's answer
    // (with a close look: only from the look altitude; the descent's views of it are not sent).
    const bool at_candidate = OfCandidate(m, revisit, p);
    const bool from_look =
        config_.revisit_look_altitude_m <= 0 || d.viewer_m.z() <= look_z + kRevisitHeightToleranceM;
    if (at_candidate && !from_look) continue;
    const bool answer = at_candidate && !revisit_seen_;
    for (const RecentReport& r : recent_) {
      known = known || ((r.position_m - p).norm() <= config_.dedupe_radius_m &&
                        in.t_s - r.t_s < config_.report_cooldown_s &&
                        (r.viewer_m - d.viewer_m).norm() < config_.report_baseline_m);
    }
    if (known && !answer) continue;
    if (answer) revisit_seen_ = true;
    recent_[recent_next_] = {p, d.viewer_m, in.t_s};
    recent_next_ = (recent_next_ + 1) % recent_.size();
    // A new report of a place supersedes an outstanding one there.
    std::erase_if(outstanding_, [&](const Outstanding& o) {
      return (o.detection.position_m.head<2>() - p).norm() <= config_.dedupe_radius_m;
    });
    if (outstanding_.size() >= recent_.size()) outstanding_.erase(outstanding_.begin());
    Propose(in, d, 1, out);
  }
}

void ScoutBehaviour::Propose(const MissionInput& in, const GroundDetection& d, int tries, MissionOutput* out) {
  const std::uint64_t seq = next_seq_++;
  const Eigen::Vector2d p = d.position_m.head<2>();
  raft::ReportSighting r{config_.name, seq, p.x(), p.y(), d.confidence};
  r.viewer_x_m = d.viewer_m.x();
  r.viewer_y_m = d.viewer_m.y();
  r.viewer_height_m = d.viewer_m.z() - config_.home_m.z();
  r.t_s = d.capture_time_s;
  out->proposals.push_back(r);
  LogEvent e(in.t_s, config_.name, "sighting_reported");
  e.Add("seq", static_cast<std::uint64_t>(seq)).Add("x", p.x(), 2).Add("y", p.y(), 2).Add("confidence", d.confidence, 3);
  if (tries > 1) e.Add("retry", tries - 1);
  out->events.push_back(std::move(e));
  outstanding_.push_back({seq, d, in.t_s, tries});
}

void ScoutBehaviour::RetrySightings(const MissionInput& in, MissionOutput* out) {
  const raft::MissionState& m = *in.mission;
  const std::size_t n = outstanding_.size();  // Propose() appends the retries behind these
  std::vector<Outstanding> keep;
  for (std::size_t i = 0; i < n; ++i) {
    const Outstanding o = outstanding_[i];
    const Eigen::Vector2d p = o.detection.position_m.head<2>();
    bool committed = false;
    for (const raft::Candidate& c : m.candidates()) {
      for (const raft::SightingView& v : c.views) committed = committed || (v.reporter == config_.name && v.seq == o.seq);
    }
    for (const raft::Victim& v : m.victims()) {
      committed = committed || (Eigen::Vector2d(v.x_m, v.y_m) - p).norm() <= config_.dedupe_radius_m;
    }
    if (committed) continue;
    if (in.t_s - o.sent_s < config_.report_retry_s) {
      keep.push_back(o);
    } else if (o.tries < config_.report_tries) {
      Propose(in, o.detection, o.tries + 1, out);
      keep.push_back(outstanding_.back());
      outstanding_.pop_back();
    }
  }
  outstanding_ = std::move(keep);
}

const raft::Candidate* ScoutBehaviour::RevisitTask(const raft::MissionState& m) const {
  if (!Active(m.phase())) return nullptr;
  for (const raft::Candidate& c : m.candidates()) {
    if (c.status == raft::CandidateStatus::kPending && c.revisit_drone == config_.name) return &c;
  }
  return nullptr;
}

void ScoutBehaviour::ProposeMiss(const MissionInput& in, MissionOutput* out) {
  const raft::Candidate* c = in.mission->FindCandidate(revisit_id_);
  SWARMBOX_CHECK(c != nullptr);
  const std::uint64_t seq = next_seq_++;
  raft::ReportMiss miss{config_.name, seq, revisit_id_, in.position_m.x(), in.position_m.y(),
                        in.position_m.z() - config_.home_m.z(), in.t_s};
  out->proposals.push_back(miss);
  ++miss_tries_;
  miss_sent_s_ = in.t_s;
  LogEvent e(in.t_s, config_.name, "miss_reported");
  e.Add("seq", static_cast<std::uint64_t>(seq))
      .Add("candidate", static_cast<std::int64_t>(revisit_id_))
      .Add("offset_m", (in.position_m.head<2>() - Eigen::Vector2d(c->x_m, c->y_m)).norm(), 2)
      .Add("height_m", miss.viewer_height_m, 1)
      .Add("look_s", in.t_s - look_start_s_, 1);
  if (miss_tries_ > 1) e.Add("retry", miss_tries_ - 1);
  out->events.push_back(std::move(e));
}

void ScoutBehaviour::RunRevisit(const MissionInput& in, MissionOutput* out) {
  const raft::Candidate* c = in.mission->FindCandidate(revisit_id_);
  SetpointRequest& sp = out->setpoint;
  const Eigen::Vector3d& p = in.position_m;
  if (c == nullptr) {  // dropped from the bounded list: Decide leaves this stage next tick
    sp.kind = SetpointKind::kPosition;
    sp.target_m = p;
    sp.yaw_rad = in.yaw_rad;
    return;
  }
  const Rect& area = config_.revisit_area;  // the nearest point a drone can hover over
  const Eigen::Vector2d at(std::clamp(c->x_m, area.x_min_m, area.x_max_m),
                           std::clamp(c->y_m, area.y_min_m, area.y_max_m));
  const double d = (p.head<2>() - at).norm();
  // Flock on the way (spacing from the others) at the search altitude, a position hold over the
  // spot at the look altitude.
  const bool near = d <= std::max(config_.home_approach_m, config_.revisit_approach_m);
  sp.kind = near ? SetpointKind::kPosition : SetpointKind::kFlock;
  const double look_z = Raised(LookAltitude());
  sp.target_m = {at.x(), at.y(), near ? look_z : Raised(Altitude())};
  sp.yaw_rad = in.yaw_rad;
  const bool under = d <= config_.revisit_arrive_m && std::abs(p.z() - look_z) <= kRevisitHeightToleranceM;
  if (look_start_s_ < 0 && under) look_start_s_ = in.t_s;
  if (look_start_s_ < 0 || revisit_seen_ || !under) return;
  const bool first = miss_tries_ == 0 && in.t_s - look_start_s_ >= config_.revisit_look_s;
  const bool retry = miss_tries_ > 0 && miss_tries_ < config_.report_tries &&
                     in.t_s - miss_sent_s_ >= config_.report_retry_s;
  if (first || retry) ProposeMiss(in, out);
}

void ScoutBehaviour::Step(const MissionInput& in, MissionOutput* out) {
  SWARMBOX_CHECK(in.mission != nullptr);
  out->Clear();
  UpdateClearance(in, out);
  // A transition re-runs the new stage at once, so the setpoint always belongs to out.mode.
  for (int pass = 0; pass < 4; ++pass) {
    Decide(in, out);
    const Stage before = stage_;
    RunStage(in, out);
    if (stage_ == before) break;
  }
  const bool reporting = stage_ == Stage::kSearching || stage_ == Stage::kSwept ||
                         stage_ == Stage::kOrbiting || stage_ == Stage::kAwaitingSector ||
                         stage_ == Stage::kRevisiting;
  if (reporting && Active(in.mission->phase())) {
    ReportSightings(in, out);
    RetrySightings(in, out);
  }
  out->mode = StageName(stage_);
}

bool ScoutBehaviour::Cruising(const MissionInput& in) const {
  switch (stage_) {
    case Stage::kAwaitingSector:
    case Stage::kSearching:
    case Stage::kSwept:
    case Stage::kOrbiting:
    case Stage::kRevisiting:
      return true;
    case Stage::kReturning:  // in its layer; not over home, where it descends (RunReturn)
      return (in.position_m.head<2>() - config_.home_m.head<2>()).norm() > 2 * config_.home_reached_m;
    default:
      return false;
  }
}

void ScoutBehaviour::UpdateClearance(const MissionInput& in, MissionOutput* out) {
  if (ClearanceRaised() && in.t_s - clearance_asked_s_ > config_.clearance_hold_s) {
    clearance_floor_z_m_ = -std::numeric_limits<double>::infinity();  // back to the cruise altitude
  }
  if (config_.min_clearance_m <= 0 || !in.obstacle_top_z_m || !Cruising(in)) return;
  const double wanted_z_m = *in.obstacle_top_z_m + config_.min_clearance_m;
  if (wanted_z_m <= Altitude()) return;
  clearance_asked_s_ = in.t_s;
  if (wanted_z_m <= clearance_floor_z_m_) return;  // already at or above it
  const bool was_raised = ClearanceRaised();
  clearance_floor_z_m_ = wanted_z_m;
  if (was_raised && wanted_z_m < clearance_logged_z_m_ + kClimbLogStep_m) return;
  clearance_logged_z_m_ = wanted_z_m;
  out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "clearance_climb")
                                      .Add("top_z", *in.obstacle_top_z_m, 2)
                                      .Add("altitude", wanted_z_m, 2)));
}

void ScoutBehaviour::Decide(const MissionInput& in, MissionOutput* out) {
  const raft::MissionState& m = *in.mission;
  const Eigen::Vector3d& p = in.position_m;
  const bool airborne = stage_ != Stage::kOnGround && stage_ != Stage::kLanded;
  const Eigen::Vector2d home_xy = config_.home_m.head<2>();

  // Leaving the mission: battery low (once) or the mission is over.
  if (airborne && stage_ != Stage::kReturning && stage_ != Stage::kLanding) {
    if (in.battery_low && !battery_low_reported_) {
      battery_low_reported_ = true;
      out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "battery_low")
                                          .Add("battery", in.battery_fraction, 3)
                                          .Add("distance_home_m", (p.head<2>() - home_xy).norm(), 1)));
    }
    if (battery_low_reported_ || Over(m.phase())) Enter(Stage::kReturning, in, out);
  }
  if (stage_ == Stage::kOnGround && !Over(m.phase()) && in.t_s >= config_.takeoff_delay_s &&
      !in.battery_low) {
    Enter(Stage::kTakingOff, in, out);
  }

  // Back to work: a sector handed over after this scout had finished, or a revisit (not with a
  // low battery).
  const raft::Candidate* revisit = battery_low_reported_ || in.battery_low ? nullptr : RevisitTask(m);
  if (Active(m.phase()) && !battery_low_reported_ && !in.battery_low && (NextSector(m) != nullptr || revisit != nullptr)) {
    if (stage_ == Stage::kReturning) Enter(Stage::kAwaitingSector, in, out);
    if (stage_ == Stage::kLanded) Enter(Stage::kTakingOff, in, out);
  }

  // Mission stages: orbit a target, search the sector, or wait for one.
  const bool on_mission = stage_ == Stage::kAwaitingSector || stage_ == Stage::kSearching ||
                          stage_ == Stage::kSwept || stage_ == Stage::kOrbiting ||
                          stage_ == Stage::kRevisiting;
  if (on_mission) DecideMissionStage(in, revisit, out);
}

void ScoutBehaviour::DecideMissionStage(const MissionInput& in, const raft::Candidate* revisit,
                                        MissionOutput* out) {
  const raft::MissionState& m = *in.mission;
  const raft::Sector* sector = Active(m.phase()) ? NextSector(m) : nullptr;
  const bool owns = Active(m.phase()) && m.SectorOf(config_.name) != nullptr;
  if (sector != nullptr && (!has_plan_ || !(*sector == planned_sector_))) StartSector(*sector, in, out);
  const raft::Victim* target = OrbitTarget(in);
  const bool still_sweeping = sector != nullptr;
  if (config_.keep_searching_during_rescue && still_sweeping && stage_ != Stage::kOrbiting) target = nullptr;
  if (revisit != nullptr) {
    if (revisit->id != revisit_id_ || stage_ != Stage::kRevisiting) {
      revisit_id_ = revisit->id;
      look_start_s_ = -1.0;
      revisit_seen_ = false;
      miss_sent_s_ = -1.0;
      miss_tries_ = 0;
    }
    Enter(Stage::kRevisiting, in, out);
  } else if (target != nullptr) {
    if (orbit_victim_ != target->id || stage_ != Stage::kOrbiting) {
      orbit_victim_ = target->id;
      orbit_reached_s_ = -1.0;
      orbit_ = OrbitWaypoints({target->x_m, target->y_m}, config_.orbit_radius_m, Altitude(),
                              config_.orbit_points, 0.0);
    }
    Enter(Stage::kOrbiting, in, out);
  } else if (sector != nullptr) {
    Enter(Stage::kSearching, in, out);
  } else if (owns) {
    Enter(config_.return_when_swept ? Stage::kReturning : Stage::kSwept, in, out);
  } else {
    Enter(Stage::kAwaitingSector, in, out);
  }
}

void ScoutBehaviour::StartSector(const raft::Sector& sector, const MissionInput& in, MissionOutput* out) {
  PlanSector(sector, in.position_m);
  out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "sector_started")
                                      .Add("lanes", static_cast<std::int64_t>(lanes_.size() / 2))
                                      .Add("x_min", sector.x_min_m, 1)
                                      .Add("y_min", sector.y_min_m, 1)
                                      .Add("x_max", sector.x_max_m, 1)
                                      .Add("y_max", sector.y_max_m, 1)));
}

void ScoutBehaviour::RunStage(const MissionInput& in, MissionOutput* out) {
  const Eigen::Vector2d home_xy = config_.home_m.head<2>();
  SetpointRequest& sp = out->setpoint;
  sp = {};
  sp.max_speed_m_s = config_.cruise_speed_m_s;
  switch (stage_) {
    case Stage::kOnGround:
    case Stage::kLanded:
      sp.kind = SetpointKind::kIdle;
      sp.target_m = in.position_m;
      sp.max_speed_m_s = 0;
      break;
    case Stage::kTakingOff: return RunTakeoff(in, out);
    case Stage::kAwaitingSector: return FlockOver(home_xy, in, out);
    case Stage::kSearching: return RunSearch(in, out);
    case Stage::kSwept: return FlockOver(AsRect(planned_sector_).center_m(), in, out);
    case Stage::kOrbiting: return RunOrbit(in, out);
    case Stage::kReturning: return RunReturn(in, out);
    case Stage::kRevisiting: return RunRevisit(in, out);
    case Stage::kLanding: return RunLanding(in, out);
  }
}

void ScoutBehaviour::RunTakeoff(const MissionInput& in, MissionOutput* out) {
  SetpointRequest& sp = out->setpoint;
  sp.kind = SetpointKind::kTakeoff;
  sp.target_m = {config_.home_m.x(), config_.home_m.y(), Altitude()};
  sp.yaw_rad = in.yaw_rad;
  if (in.position_m.z() >= Altitude() - kTakeoffDoneBelowAltitude_m) Enter(Stage::kAwaitingSector, in, out);
}

void ScoutBehaviour::FlockOver(const Eigen::Vector2d& xy_m, const MissionInput& in, MissionOutput* out) const {
  SetpointRequest& sp = out->setpoint;
  sp.kind = SetpointKind::kFlock;
  sp.target_m = {xy_m.x(), xy_m.y(), Raised(Altitude())};
  sp.yaw_rad = in.yaw_rad;
}

void ScoutBehaviour::RunLanding(const MissionInput& in, MissionOutput* out) {
  SetpointRequest& sp = out->setpoint;
  sp.kind = SetpointKind::kLand;
  sp.target_m = config_.home_m;
  sp.yaw_rad = in.yaw_rad;
  if (in.position_m.z() <= config_.home_m.z() + config_.base_height_m + kOnGroundAboveBase_m &&
      in.velocity_m_s.norm() < kOnGroundSpeed_m_s) {
    Enter(Stage::kLanded, in, out);
  }
}

void ScoutBehaviour::RunSearch(const MissionInput& in, MissionOutput* out) {
  const Eigen::Vector3d& p = in.position_m;
  SetpointRequest& sp = out->setpoint;
  if (rejoin_m_ && (*rejoin_m_ - p.head<2>()).norm() <= config_.waypoint_radius_m) rejoin_m_.reset();
  if (rejoin_m_) {  // back to the lane first (Enter)
    sp.kind = SetpointKind::kFlock;
    sp.target_m = {rejoin_m_->x(), rejoin_m_->y(), Raised(lanes_[lane_index_].position_m.z())};
    sp.yaw_rad = lanes_[lane_index_].yaw_rad;
    return;
  }
  if ((lanes_[lane_index_].position_m.head<2>() - p.head<2>()).norm() <= config_.waypoint_radius_m) {
    ++lane_index_;
    if (lane_index_ == lanes_.size()) {
      swept_.push_back(planned_sector_);
      out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "sector_swept")
                                          .Add("lanes", static_cast<std::int64_t>(lanes_.size() / 2))));
      Enter(Stage::kSwept, in, out);
      return;
    }
    if (lane_index_ % 2 == 0) {  // the end of a lane
      out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "sector_progress")
                                          .Add("lanes_done", static_cast<std::int64_t>(lane_index_ / 2))
                                          .Add("lanes", static_cast<std::int64_t>(lanes_.size() / 2))));
    }
  }
  sp.kind = SetpointKind::kFlock;
  sp.target_m = lanes_[lane_index_].position_m;
  sp.target_m.z() = Raised(sp.target_m.z());
  sp.yaw_rad = lanes_[lane_index_].yaw_rad;
}

void ScoutBehaviour::RunOrbit(const MissionInput& in, MissionOutput* out) {
  const Eigen::Vector3d& p = in.position_m;
  const raft::Victim* v = in.mission->FindVictim(orbit_victim_);
  SWARMBOX_CHECK(v != nullptr);
  const Eigen::Vector2d c(v->x_m, v->y_m);
  const double from_centre = (p.head<2>() - c).norm();
  if (orbit_reached_s_ < 0 && std::abs(from_centre - config_.orbit_radius_m) < 5.0) {
    orbit_reached_s_ = in.t_s;
  }
  const std::size_t k =
      NextOrbitWaypoint(orbit_, c, p.head<2>(), config_.orbit_lead_rad);
  SetpointRequest& sp = out->setpoint;
  sp.kind = SetpointKind::kFlock;
  sp.target_m = orbit_[k].position_m;
  sp.target_m.z() = Raised(sp.target_m.z());
  sp.yaw_rad = orbit_[k].yaw_rad;
  if ((!config_.lifter_present || config_.return_when_swept) && orbit_reached_s_ >= 0 &&
      in.t_s - orbit_reached_s_ >= config_.orbit_time_s) {
    handled_.insert(orbit_victim_);
    out->events.push_back(std::move(LogEvent(in.t_s, config_.name, "victim_handled")
                                        .Add("id", static_cast<std::int64_t>(orbit_victim_))
                                        .Add("orbit_s", in.t_s - orbit_reached_s_, 1)));
  }
}

void ScoutBehaviour::RunReturn(const MissionInput& in, MissionOutput* out) {
  const Eigen::Vector3d& p = in.position_m;
  const Eigen::Vector2d home_xy = config_.home_m.head<2>();
  SetpointRequest& sp = out->setpoint;
  const double d = (p.head<2>() - home_xy).norm();
  sp.kind = d > config_.home_approach_m ? SetpointKind::kFlock : SetpointKind::kPosition;
  const double layer_z = Altitude() + config_.return_layer * config_.return_layer_m;
  const double approach_z =
      config_.approach_height_m > 0 ? config_.home_m.z() + config_.approach_height_m : layer_z;
  // Home in this scout's layer, down only once over home (within 2 x home_reached_m): on a
  // 4 m take-off grid a drone descending on the slant of the last approach_m would pass
  // through its neighbours' columns at their heights; vertically it stays in its own.
  sp.target_m = {home_xy.x(), home_xy.y(), d > 2 * config_.home_reached_m ? Raised(layer_z) : approach_z};
  sp.yaw_rad = in.yaw_rad;
  if (d <= config_.home_reached_m && p.z() <= approach_z + 1.0) Enter(Stage::kLanding, in, out);
}

}  // namespace swarmbox::swarm
