#include "swarmbox/swarm/leader_planner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::swarm {
namespace {

using raft::MissionPhase;
using raft::VictimStatus;

bool IsOneOf(const std::string& mode, std::initializer_list<std::string_view> modes) {
  return std::find(modes.begin(), modes.end(), mode) != modes.end();
}

// A scout that has nothing left to sweep (or has left the search: battery, mission over).
bool ScoutDone(const std::string& mode) {
  return IsOneOf(mode, {"swept", "returning", "landing", "landed", "on_ground"});
}

// How soon a scout could take over a sector: 0 idle in the air, 1 busy (or climbing), 2 on its
// way down or on the ground (it must take off again).
int Availability(const std::string& mode) {
  if (IsOneOf(mode, {"swept", "awaiting_sector", "returning"})) return 0;
  if (IsOneOf(mode, {"landing", "landed", "on_ground"})) return 2;
  return 1;
}

// A live scout that could take over a sector, and how soon (Availability; raised as it gets work).
struct ScoutRank {
  const RosterEntry* entry;
  int rank;
};

// The scouts that take over the orphaned sector `rect`, in name order (the same plan whoever
// computes it): at most as many as near-square pieces fit, the most available and nearest first.
std::vector<std::string> PickTakers(const Rect& rect, std::vector<ScoutRank>* cands) {
  const double long_m = std::max(rect.width_m(), rect.height_m());
  const double short_m = std::min(rect.width_m(), rect.height_m());
  const std::size_t fit = static_cast<std::size_t>(std::max(1.0, std::round(long_m / short_m)));
  const std::size_t k = std::min(cands->size(), fit);
  const Eigen::Vector2d c = rect.center_m();
  std::sort(cands->begin(), cands->end(), [&](const ScoutRank& x, const ScoutRank& y) {
    if (x.rank != y.rank) return x.rank < y.rank;
    const double dx = (x.entry->position_m - c).norm(), dy = (y.entry->position_m - c).norm();
    if (dx != dy) return dx < dy;
    return x.entry->name < y.entry->name;
  });
  std::vector<std::string> to;
  for (std::size_t i = 0; i < k; ++i) {
    to.push_back((*cands)[i].entry->name);
    (*cands)[i].rank = std::max((*cands)[i].rank, 1) + 1;  // has work now: others first next time
  }
  std::sort(to.begin(), to.end());
  return to;
}

// event=sighting: one view of candidate `c` (its index `k`) and the fused belief up to it.
LogEvent SightingEvent(double t_s, const std::string& leader, const raft::Candidate& c, std::size_t k,
                       const FusionParams& fusion) {
  raft::Candidate upto = c;
  upto.views.assign(c.views.begin(), c.views.begin() + static_cast<std::ptrdiff_t>(k + 1));
  const FusionAssessment a = AssessCandidate(upto, fusion);
  const raft::SightingView& v = c.views[k];
  char viewer[64];
  std::snprintf(viewer, sizeof viewer, "%.1f:%.1f:%.1f", v.viewer_x_m, v.viewer_y_m, v.viewer_height_m);
  LogEvent e(t_s, leader, "sighting");
  e.Add("candidate", static_cast<std::int64_t>(c.id))
      .Add("reporter", v.reporter)
      .Add("seen", v.detected)
      .Add("confidence", v.detected ? v.confidence : 0.0, 3)
      .Add("x", v.x_m, 2)
      .Add("y", v.y_m, 2)
      .Add("viewer", viewer)
      .Add("capture_t", v.t_s, 2)
      .Add("belief", a.belief, 3)
      .Add("counted", a.counted_detections)
      .Add("counted_misses", a.counted_misses);
  return e;
}

// event=confirmed / event=rejected for a decided candidate, with its evidence.
LogEvent DecisionEvent(double t_s, const std::string& leader, const raft::Candidate& c,
                       const FusionParams& fusion) {
  const FusionAssessment a = AssessCandidate(c, fusion);
  const bool confirmed = c.status == raft::CandidateStatus::kConfirmed;
  LogEvent e(t_s, leader, confirmed ? "confirmed" : "rejected");
  if (confirmed) {
    e.Add("victim", static_cast<std::int64_t>(c.victim_id));
  } else {
    // Why, from the decision's own belief: Decide rejects on belief only at <= reject_belief, so a
    // rejection above it is one whose revisits ran out. (Assessing the candidate again cannot
    // tell: Decide leaves a candidate no longer pending undecided = false.)
    e.Add("reason", c.belief <= fusion.reject_belief ? "belief" : "undecided");
  }
  e.Add("decided_belief", c.belief, 3);
  AddEvidence(e, c, a);
  return e;
}

}  // namespace

LeaderPlanner::LeaderPlanner(LeaderConfig config) : config_(std::move(config)) {
  SWARMBOX_CHECK(config_.search_area.width_m() > 0 && config_.search_area.height_m() > 0);
  SWARMBOX_CHECK(config_.retry_s > 0);
  SWARMBOX_CHECK(config_.member_timeout_s > 0 && config_.assignment_settle_s >= 0);
  SWARMBOX_CHECK(config_.member_min_wall_s >= 0);
  CheckFusionParams(config_.fusion);
}

bool LeaderPlanner::Due(const std::string& key, double t_s) {
  auto it = last_proposed_s_.find(key);
  if (it != last_proposed_s_.end() && t_s - it->second < config_.retry_s) return false;
  last_proposed_s_[key] = t_s;
  return true;
}

void LeaderPlanner::Track(double t_s, const raft::MissionState& m, double wall_s) {
  const bool first = !tracking_;
  if (first) {
    tracking_ = true;
    first_s_ = t_s;
    first_wall_s_ = wall_s;
  }
  wall_s_ = wall_s;
  if (first || !(m.sectors() == sectors_)) {
    sectors_ = m.sectors();
    sectors_changed_s_ = t_s;
  }
  if (t_s != tracked_s_) evidence_events_.clear();  // a new tick: the old ones were the last tick's
  tracked_s_ = t_s;
  TrackCandidates(t_s, m, first);
}

void LeaderPlanner::TrackCandidates(double t_s, const raft::MissionState& m, bool learn_only) {
  for (const raft::Candidate& c : m.candidates()) {
    SeenCandidate& seen = seen_[c.id];
    if (learn_only) {
      seen = {c.views.size(), c.status, c.revisit_drone};
      continue;
    }
    if (seen.views == c.views.size() && seen.status == c.status && seen.revisit_drone == c.revisit_drone) continue;
    // The fused belief after each new view, in record order.
    for (std::size_t k = seen.views; k < c.views.size(); ++k) {
      evidence_events_.push_back(SightingEvent(t_s, config_.name, c, k, config_.fusion));
    }
    if (!c.revisit_drone.empty() && c.revisit_drone != seen.revisit_drone) {
      evidence_events_.push_back(std::move(LogEvent(t_s, config_.name, "revisit")
                                               .Add("candidate", static_cast<std::int64_t>(c.id))
                                               .Add("drone", c.revisit_drone)
                                               .Add("x", c.x_m, 2)
                                               .Add("y", c.y_m, 2)
                                               .Add("revisits_done", static_cast<std::int64_t>(c.revisits))));
    }
    if (c.status != seen.status && c.status != raft::CandidateStatus::kPending) {
      evidence_events_.push_back(DecisionEvent(t_s, config_.name, c, config_.fusion));
    }
    seen = {c.views.size(), c.status, c.revisit_drone};
  }
}

bool LeaderPlanner::PlanCandidates(double t_s, const raft::MissionState& m, std::span<const RosterEntry> roster,
                                   MissionOutput* out) {
  bool pending = false;
  // Scouts already sent somewhere: one revisit each at a time.
  std::set<std::string> busy;
  for (const raft::Candidate& c : m.candidates()) {
    if (!c.revisit_drone.empty() && c.status == raft::CandidateStatus::kPending) busy.insert(c.revisit_drone);
  }
  for (const raft::Candidate& c : m.candidates()) {
    if (c.status == raft::CandidateStatus::kConfirmed) continue;
    const FusionAssessment a = AssessCandidate(c, config_.fusion);
    const std::string id = std::to_string(c.id);
    if (a.decision == FusionDecision::kConfirm) {
      pending = pending || c.status == raft::CandidateStatus::kPending;
      if (Due("confirm:" + id, t_s)) out->proposals.push_back(raft::ConfirmSighting{c.id, a.belief});
      continue;
    }
    if (c.status != raft::CandidateStatus::kPending) continue;  // rejected: new evidence may still confirm it
    pending = true;
    if (a.decision == FusionDecision::kReject) {
      if (Due("reject:" + id, t_s)) out->proposals.push_back(raft::RejectSighting{c.id, a.belief});
      continue;
    }
    if (!RevisitNeeded(t_s, c, a)) continue;
    const RosterEntry* best = PickRevisitor(c, roster, busy);
    if (best == nullptr) continue;
    if (Due("revisit:" + id, t_s)) {
      out->proposals.push_back(raft::RequestRevisit{c.id, best->name, t_s});
      busy.insert(best->name);
    }
  }
  return pending;
}

bool LeaderPlanner::RevisitNeeded(double t_s, const raft::Candidate& c, const FusionAssessment& a) const {
  if (c.revisit_drone.empty()) return t_s - a.last_view_s >= config_.fusion.revisit_after_s;
  return GoneOwner(t_s, c.revisit_drone) || t_s - c.revisit_t_s >= config_.fusion.revisit_timeout_s;
}

const RosterEntry* LeaderPlanner::PickRevisitor(const raft::Candidate& c, std::span<const RosterEntry> roster,
                                                const std::set<std::string>& busy) const {
  const Eigen::Vector2d at(c.x_m, c.y_m);
  const RosterEntry* best = nullptr;
  int best_rank = 0;
  double best_d = 0;
  for (const RosterEntry& r : roster) {
    if (r.role != Role::kScout || !Alive(r) || busy.count(r.name) != 0 || r.name == c.revisit_drone) continue;
    if (IsOneOf(r.mode, {"taking_off", "landing"})) continue;
    const int rank = Availability(r.mode);
    const double d = (r.position_m - at).norm();
    if (best == nullptr || rank < best_rank || (rank == best_rank && (d < best_d || (d == best_d && r.name < best->name)))) {
      best = &r;
      best_rank = rank;
      best_d = d;
    }
  }
  return best;
}

void LeaderPlanner::Index(std::span<const RosterEntry> roster) {
  by_name_.clear();
  for (const RosterEntry& r : roster) by_name_.push_back(&r);
  std::sort(by_name_.begin(), by_name_.end(),
            [](const RosterEntry* a, const RosterEntry* b) { return a->name < b->name; });
}

const RosterEntry* LeaderPlanner::Find(const std::string& drone) const {
  const auto it = std::lower_bound(by_name_.begin(), by_name_.end(), drone,
                                   [](const RosterEntry* e, const std::string& n) { return e->name < n; });
  return it != by_name_.end() && (*it)->name == drone ? *it : nullptr;
}

bool LeaderPlanner::GoneOwner(double t_s, const std::string& drone) const {
  if (const RosterEntry* r = Find(drone)) return !Alive(*r);
  // Never heard (or not a mission agent): gone once everyone had time to be heard, on both clocks
  // (NaN wall times: no wall clock, the comparison below is false).
  return t_s - first_s_ >= config_.member_timeout_s && !(wall_s_ - first_wall_s_ < config_.member_min_wall_s);
}

void LeaderPlanner::ReportMembers(double t_s, std::span<const RosterEntry> roster, MissionOutput* out) {
  for (const RosterEntry& r : roster) {
    const bool alive = Alive(r);
    if (!alive && lost_.insert(r.name).second) {
      LogEvent e(t_s, config_.name, "member_lost");
      e.Add("drone", r.name).Add("role", RoleName(r.role)).Add("silent_s", r.age_s, 1);
      if (std::isfinite(r.wall_age_s)) e.Add("silent_wall_s", r.wall_age_s, 1);
      out->events.push_back(std::move(e.Add("last_mode", r.mode)));
    } else if (alive && lost_.erase(r.name) != 0) {
      out->events.push_back(std::move(LogEvent(t_s, config_.name, "member_back")
                                          .Add("drone", r.name)
                                          .Add("mode", r.mode)));
    }
  }
}

std::optional<raft::AssignSectors> LeaderPlanner::Reassign(double t_s, const raft::MissionState& m,
                                                           std::span<const RosterEntry> roster,
                                                           MissionOutput* out) const {
  std::vector<raft::Sector> keep, orphans;
  for (const raft::Sector& s : m.sectors()) (GoneOwner(t_s, s.drone) ? orphans : keep).push_back(s);
  if (orphans.empty()) return std::nullopt;
  std::vector<ScoutRank> cands;
  for (const RosterEntry& r : roster) {
    if (r.role == Role::kScout && Alive(r)) cands.push_back({&r, Availability(r.mode)});
  }
  if (cands.empty()) return std::nullopt;
  // Lane progress is not replicated (a dead scout's last lane is in no committed state a new
  // leader could read), so the whole sector is handed over. It is cut across its longer side into
  // at most as many near-square pieces as fit (about as long as the sector is wide, so lanes stay
  // long and no swath is wasted), one per scout: the re-sweep costs a fraction of a sector.
  raft::AssignSectors a;
  a.sectors = std::move(keep);
  for (const raft::Sector& o : orphans) {
    const Rect rect = AsRect(o);
    std::string list;
    for (raft::Sector& piece : PartitionArea(rect, PickTakers(rect, &cands))) {
      list += (list.empty() ? "" : ",") + piece.drone;
      a.sectors.push_back(std::move(piece));
    }
    out->events.push_back(std::move(LogEvent(t_s, config_.name, "sector_reassigned")
                                        .Add("from", o.drone)
                                        .Add("to", list)
                                        .Add("x_min", o.x_min_m, 1)
                                        .Add("y_min", o.y_min_m, 1)
                                        .Add("x_max", o.x_max_m, 1)
                                        .Add("y_max", o.y_max_m, 1)));
  }
  return a;
}

// The swarm as one Step sees it.
struct LeaderPlanner::Fleet {
  std::vector<std::string> scouts;        // live ones
  std::vector<Eigen::Vector2d> scout_xy;  // where each is
  const RosterEntry* lifter = nullptr;    // the first live lifter
  bool scouts_airborne = true;
  bool all_down = true;                   // every live drone landed or on the ground
};

void LeaderPlanner::Step(double t_s, const raft::MissionState& m,
                         std::span<const RosterEntry> roster, MissionOutput* out, double wall_s) {
  Track(t_s, m, wall_s);
  for (LogEvent& e : evidence_events_) out->events.push_back(std::move(e));
  evidence_events_.clear();
  Index(roster);
  ReportMembers(t_s, roster, out);
  const Fleet fleet = Survey(roster);
  const bool orphans = ProposeReassign(t_s, m, roster, out);
  const bool scouts_done = ScoutsDone(t_s, m, roster, orphans);
  const bool active = m.phase() == MissionPhase::kSearch || m.phase() == MissionPhase::kConverge ||
                      m.phase() == MissionPhase::kRescue;
  const bool undecided = active && PlanCandidates(t_s, m, roster, out);
  switch (m.phase()) {
    case MissionPhase::kIdle:
      PlanStart(t_s, m, fleet, out);
      break;
    case MissionPhase::kSearch:
    case MissionPhase::kConverge: {
      const bool rescue_running =
          std::any_of(m.victims().begin(), m.victims().end(),
                      [](const raft::Victim& v) { return v.status == VictimStatus::kBeingRescued; });
      PlanSearch(t_s, m, fleet, scouts_done && !rescue_running && !undecided, out);
      break;
    }
    case MissionPhase::kRescue:
      break;  // the lifter proposes MarkRescued
    case MissionPhase::kReturn:
      if (fleet.all_down && Due("complete", t_s)) out->proposals.push_back(raft::CompleteMission{});
      break;
    case MissionPhase::kComplete:
      ReportComplete(t_s, m, out);
      break;
  }
}

LeaderPlanner::Fleet LeaderPlanner::Survey(std::span<const RosterEntry> roster) const {
  Fleet f;
  for (const RosterEntry& r : roster) {
    if (!Alive(r)) continue;  // a dead drone's last mode says nothing any more
    f.all_down = f.all_down && IsOneOf(r.mode, {"landed", "on_ground"});
    if (r.role == Role::kLifter) {
      if (f.lifter == nullptr) f.lifter = &r;
      continue;
    }
    f.scouts.push_back(r.name);
    f.scout_xy.push_back(r.position_m);
    f.scouts_airborne = f.scouts_airborne && !IsOneOf(r.mode, {"on_ground", "taking_off"});
  }
  return f;
}

bool LeaderPlanner::ProposeReassign(double t_s, const raft::MissionState& m,
                                    std::span<const RosterEntry> roster, MissionOutput* out) {
  // Sectors of gone members go to live scouts first (any phase with sectors still to search).
  bool orphans = false;
  const bool searching = m.phase() == MissionPhase::kIdle || m.phase() == MissionPhase::kSearch ||
                         m.phase() == MissionPhase::kConverge || m.phase() == MissionPhase::kRescue;
  if (!searching || m.sectors().empty()) return false;
  MissionOutput scratch;
  if (auto a = Reassign(t_s, m, roster, &scratch)) {
    orphans = true;
    if (Due("reassign", t_s)) {
      out->proposals.push_back(std::move(*a));
      for (LogEvent& e : scratch.events) out->events.push_back(std::move(e));
    }
  } else {
    for (const raft::Sector& s : m.sectors()) orphans = orphans || GoneOwner(t_s, s.drone);
  }
  return orphans;
}

bool LeaderPlanner::ScoutsDone(double t_s, const raft::MissionState& m,
                               std::span<const RosterEntry> roster, bool orphans) {
  // The search is finished when every sector has a live owner that swept it (or left), every
  // live scout without a sector idles, and no hand-over is younger than the settle time.
  bool scouts_done = !orphans && t_s - sectors_changed_s_ >= config_.assignment_settle_s;
  owners_.clear();
  if (scouts_done) {
    for (const raft::Sector& s : m.sectors()) owners_.push_back(&s.drone);
    std::sort(owners_.begin(), owners_.end(),
              [](const std::string* a, const std::string* b) { return *a < *b; });
  }
  for (const RosterEntry& r : roster) {
    if (!scouts_done) break;
    if (r.role != Role::kScout || !Alive(r)) continue;
    const bool owns = std::binary_search(owners_.begin(), owners_.end(), &r.name,
                                         [](const std::string* a, const std::string* b) { return *a < *b; });
    scouts_done = ScoutDone(r.mode) || (!owns && r.mode == "awaiting_sector");
  }
  return scouts_done;
}

const raft::Victim* LeaderPlanner::FirstUnhandled(const raft::MissionState& m) const {
  for (const raft::Victim& v : m.victims()) {
    if (v.status == VictimStatus::kConfirmed && handled_.count(v.id) == 0) return &v;
  }
  return nullptr;
}

void LeaderPlanner::PlanStart(double t_s, const raft::MissionState& m, const Fleet& fleet,
                              MissionOutput* out) {
  if (fleet.scouts.empty() || !(fleet.scouts_airborne || t_s >= config_.start_timeout_s) ||
      !Due("start", t_s)) {
    return;
  }
  if (m.sectors().empty()) {
    // One proposal for every scout: each gets the cell of the grid that matches its place
    // in the swarm (PartitionOrder), so that nobody crosses another's path to its sector.
    std::vector<std::string> ordered;
    ordered.reserve(fleet.scouts.size());
    for (const std::size_t i : PartitionOrder(config_.search_area, fleet.scouts, fleet.scout_xy)) {
      ordered.push_back(fleet.scouts[i]);
    }
    out->proposals.push_back(raft::AssignSectors{PartitionArea(config_.search_area, ordered)});
  }
  out->proposals.push_back(raft::StartSearch{});
}

void LeaderPlanner::PlanSearch(double t_s, const raft::MissionState& m, const Fleet& fleet,
                               bool search_finished, MissionOutput* out) {
  const raft::Victim* candidate = FirstUnhandled(m);  // confirmed, not yet rescued or handled
  const std::uint32_t target = m.target_victim();
  const raft::Victim* tv = m.FindVictim(target);
  if (m.phase() == MissionPhase::kConverge && tv != nullptr &&
      tv->status == VictimStatus::kConfirmed && handled_.count(target) == 0) {
    if (fleet.lifter != nullptr) {
      if (IsOneOf(fleet.lifter->mode, {"on_ground", "standby"}) &&
          Due("rescue:" + std::to_string(target), t_s)) {
        out->proposals.push_back(raft::BeginRescue{target, fleet.lifter->name});
      }
      return;
    }
    // No lifter: the scouts orbit the victim for handle_time_s, then it counts as handled.
    auto [it, inserted] = converge_since_s_.emplace(target, t_s);
    if (t_s - it->second < config_.handle_time_s) return;
    handled_.insert(target);
    out->events.push_back(std::move(LogEvent(t_s, config_.name, "victim_handled")
                                        .Add("id", static_cast<std::int64_t>(target))
                                        .Add("by", "orbit")));
    candidate = FirstUnhandled(m);
  }
  if (candidate != nullptr) {
    if (Due("converge:" + std::to_string(candidate->id), t_s)) {
      out->proposals.push_back(raft::ConvergeOn{candidate->id});
    }
  } else if (search_finished && Due("return", t_s)) {
    out->proposals.push_back(raft::ReturnHome{});
  }
}

void LeaderPlanner::ReportComplete(double t_s, const raft::MissionState& m, MissionOutput* out) {
  if (complete_reported_) return;
  complete_reported_ = true;
  std::int64_t rescued = 0;
  for (const raft::Victim& v : m.victims()) rescued += v.status == VictimStatus::kRescued ? 1 : 0;
  out->events.push_back(std::move(LogEvent(t_s, config_.name, "mission_complete")
                                      .Add("victims", static_cast<std::int64_t>(m.victims().size()))
                                      .Add("rescued", rescued)
                                      .Add("handled", static_cast<std::int64_t>(handled_.size()))));
}

}  // namespace swarmbox::swarm
