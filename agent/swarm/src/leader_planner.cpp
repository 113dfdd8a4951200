#include "swarmbox/swarm/leader_planner.hpp"

#include <algorithm>
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

}  // namespace

LeaderPlanner::LeaderPlanner(LeaderConfig config) : config_(std::move(config)) {
  SWARMBOX_CHECK(config_.search_area.width_m() > 0 && config_.search_area.height_m() > 0);
  SWARMBOX_CHECK(config_.retry_s > 0);
}

bool LeaderPlanner::Due(const std::string& key, double t_s) {
  auto it = last_proposed_s_.find(key);
  if (it != last_proposed_s_.end() && t_s - it->second < config_.retry_s) return false;
  last_proposed_s_[key] = t_s;
  return true;
}

void LeaderPlanner::Step(double t_s, const raft::MissionState& m,
                         std::span<const RosterEntry> roster, MissionOutput* out) {
  std::vector<std::string> scouts;
  const RosterEntry* lifter = nullptr;
  bool scouts_airborne = true;
  bool scouts_done = true;
  bool all_down = true;
  for (const RosterEntry& r : roster) {
    all_down = all_down && IsOneOf(r.mode, {"landed", "on_ground"});
    if (r.role == Role::kLifter) {
      if (lifter == nullptr) lifter = &r;
      continue;
    }
    scouts.push_back(r.name);
    scouts_airborne = scouts_airborne && !IsOneOf(r.mode, {"on_ground", "taking_off"});
    scouts_done = scouts_done &&
                  IsOneOf(r.mode, {"swept", "returning", "landing", "landed", "on_ground"});
  }
  std::sort(scouts.begin(), scouts.end());

  const raft::Victim* candidate = nullptr;  // confirmed, not yet rescued or handled
  bool rescue_running = false;
  for (const raft::Victim& v : m.victims()) {
    if (v.status == VictimStatus::kBeingRescued) rescue_running = true;
    if (v.status == VictimStatus::kConfirmed && handled_.count(v.id) == 0 && candidate == nullptr) {
      candidate = &v;
    }
  }

  switch (m.phase()) {
    case MissionPhase::kIdle:
      if (!scouts.empty() && (scouts_airborne || t_s >= config_.start_timeout_s) &&
          Due("start", t_s)) {
        if (m.sectors().empty()) {
          out->proposals.push_back(raft::AssignSectors{PartitionArea(config_.search_area, scouts)});
        }
        out->proposals.push_back(raft::StartSearch{});
      }
      break;
    case MissionPhase::kSearch:
    case MissionPhase::kConverge: {
      const std::uint32_t target = m.target_victim();
      const raft::Victim* tv = m.FindVictim(target);
      if (m.phase() == MissionPhase::kConverge && tv != nullptr &&
          tv->status == VictimStatus::kConfirmed && handled_.count(target) == 0) {
        if (lifter != nullptr) {
          if (IsOneOf(lifter->mode, {"on_ground", "standby"}) && Due("rescue:" + std::to_string(target), t_s)) {
            out->proposals.push_back(raft::BeginRescue{target, lifter->name});
          }
          break;
        }
        auto [it, inserted] = converge_since_s_.emplace(target, t_s);
        if (t_s - it->second < config_.handle_time_s) break;
        handled_.insert(target);
        out->events.push_back(std::move(LogEvent(t_s, config_.name, "victim_handled")
                                            .Add("id", static_cast<std::int64_t>(target))
                                            .Add("by", "orbit")));
        candidate = nullptr;
        for (const raft::Victim& v : m.victims()) {
          if (v.status == VictimStatus::kConfirmed && handled_.count(v.id) == 0) {
            candidate = &v;
            break;
          }
        }
      }
      if (candidate != nullptr) {
        if (Due("converge:" + std::to_string(candidate->id), t_s)) {
          out->proposals.push_back(raft::ConvergeOn{candidate->id});
        }
      } else if (scouts_done && !rescue_running && Due("return", t_s)) {
        out->proposals.push_back(raft::ReturnHome{});
      }
      break;
    }
    case MissionPhase::kRescue:
      break;  // the lifter proposes MarkRescued
    case MissionPhase::kReturn:
      if (all_down && Due("complete", t_s)) out->proposals.push_back(raft::CompleteMission{});
      break;
    case MissionPhase::kComplete:
      if (!complete_reported_) {
        complete_reported_ = true;
        std::int64_t rescued = 0;
        for (const raft::Victim& v : m.victims()) rescued += v.status == VictimStatus::kRescued ? 1 : 0;
        out->events.push_back(std::move(LogEvent(t_s, config_.name, "mission_complete")
                                            .Add("victims", static_cast<std::int64_t>(m.victims().size()))
                                            .Add("rescued", rescued)
                                            .Add("handled", static_cast<std::int64_t>(handled_.size()))));
      }
      break;
  }
}

}  // namespace swarmbox::swarm
