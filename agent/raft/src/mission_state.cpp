#include "swarmbox/raft/mission_state.hpp"

#include <cmath>

#include "swarmbox/raft/detail/byte_io.hpp"
#include "swarmbox/raft/detail/mission_io.hpp"
#include "swarmbox/raft/detail/overloaded.hpp"

namespace swarmbox::raft {

std::string_view PhaseName(MissionPhase phase) {
  switch (phase) {
    case MissionPhase::kIdle: return "IDLE";
    case MissionPhase::kSearch: return "SEARCH";
    case MissionPhase::kConverge: return "CONVERGE";
    case MissionPhase::kRescue: return "RESCUE";
    case MissionPhase::kReturn: return "RETURN";
    case MissionPhase::kComplete: return "COMPLETE";
  }
  return "UNKNOWN";
}

std::string_view VictimStatusName(VictimStatus status) {
  switch (status) {
    case VictimStatus::kConfirmed: return "confirmed";
    case VictimStatus::kBeingRescued: return "being_rescued";
    case VictimStatus::kRescued: return "rescued";
  }
  return "unknown";
}

namespace {

using detail::Overloaded;

bool Finite(double v) { return std::isfinite(v); }

double Distance(double ax, double ay, double bx, double by) { return std::hypot(ax - bx, ay - by); }

// A kVictimConfirmed / kVictimStatus event at `phase` and log `index`: `v` after the change.
MissionEvent VictimEvent(MissionEvent::Kind kind, MissionPhase phase, std::uint64_t index,
                         const Victim& v) {
  MissionEvent e;
  e.kind = kind;
  e.phase = phase;
  e.index = index;
  e.victim = v;
  return e;
}

}  // namespace

const Victim* MissionState::FindVictim(std::uint32_t id) const {
  for (const Victim& v : victims_) {
    if (v.id == id) return &v;
  }
  return nullptr;
}

const Sector* MissionState::SectorOf(std::string_view drone) const {
  for (const Sector& s : sectors_) {
    if (s.drone == drone) return &s;
  }
  return nullptr;
}

ApplyResult MissionState::Reject(std::string reason) const {
  ApplyResult r;
  r.accepted = false;
  r.reason = std::move(reason);
  return r;
}

void MissionState::SetPhase(MissionPhase phase, ApplyResult* r) {
  if (phase == phase_) return;
  phase_ = phase;
  MissionEvent e;
  e.kind = MissionEvent::Kind::kPhase;
  e.phase = phase;
  e.index = applied_index_;
  r->events.push_back(e);
}

Victim* MissionState::NearVictim(double x_m, double y_m) {
  Victim* best = nullptr;
  double best_d = kConfirmRadiusM;
  for (Victim& v : victims_) {
    const double d = Distance(v.x_m, v.y_m, x_m, y_m);
    if (d <= best_d) {
      best = &v;
      best_d = d;
    }
  }
  return best;
}

Victim& MissionState::AddVictim(double x_m, double y_m, std::vector<std::string> by,
                                ApplyResult* r) {
  Victim v;
  v.id = next_victim_id_++;
  v.x_m = x_m;
  v.y_m = y_m;
  v.confirmed_by = std::move(by);
  victims_.push_back(std::move(v));
  r->events.push_back(
      VictimEvent(MissionEvent::Kind::kVictimConfirmed, phase_, applied_index_, victims_.back()));
  return victims_.back();
}

void MissionState::Skip(std::uint64_t index) {
  SWARMBOX_CHECK(index > applied_index_);
  applied_index_ = index;
}

ApplyResult MissionState::ApplyEncoded(std::uint64_t index, std::span<const std::uint8_t> data) {
  auto cmd = DecodeCommand(data);
  if (!cmd) {
    Skip(index);
    return Reject("undecodable command: " + cmd.error().message());
  }
  return Apply(index, *cmd);
}

ApplyResult MissionState::Apply(std::uint64_t index, const MissionCommand& command) {
  SWARMBOX_CHECK(index > applied_index_);
  applied_index_ = index;
  const MissionPhase phase = phase_;
  const bool active = phase == MissionPhase::kSearch || phase == MissionPhase::kConverge ||
                      phase == MissionPhase::kRescue;
  const std::string in_phase = std::string(" in phase ") + std::string(PhaseName(phase));
  ApplyResult r;
  r.accepted = true;
  return std::visit(
      Overloaded{
          [&](const StartSearch&) -> ApplyResult {
            if (phase != MissionPhase::kIdle) return Reject("cannot start search" + in_phase);
            SetPhase(MissionPhase::kSearch, &r);
            return r;
          },
          [&](const AssignSectors& c) -> ApplyResult {
            if (phase == MissionPhase::kComplete) return Reject("cannot assign sectors" + in_phase);
            for (const Sector& s : c.sectors) {
              if (s.drone.empty()) return Reject("sector without a drone");
              if (!Finite(s.x_min_m) || !Finite(s.y_min_m) || !Finite(s.x_max_m) ||
                  !Finite(s.y_max_m) || s.x_min_m >= s.x_max_m || s.y_min_m >= s.y_max_m) {
                return Reject("sector of " + s.drone + " is not a rectangle with min < max");
              }
            }
            sectors_ = c.sectors;
            return r;
          },
          [&](const ReportSighting& c) -> ApplyResult {
            if (!active) return Reject("sighting ignored" + in_phase);
            return ApplySighting(c);
          },
          [&](const ConfirmVictim& c) -> ApplyResult {
            if (!active) return Reject("cannot confirm a victim" + in_phase);
            if (!Finite(c.x_m) || !Finite(c.y_m)) return Reject("victim position is not finite");
            if (Victim* v = NearVictim(c.x_m, c.y_m)) {
              return Reject("victim " + std::to_string(v->id) + " is already confirmed there");
            }
            AddVictim(c.x_m, c.y_m, {c.by}, &r);
            return r;
          },
          [&](const ConvergeOn& c) -> ApplyResult {
            if (phase != MissionPhase::kSearch && phase != MissionPhase::kConverge) {
              return Reject("cannot converge" + in_phase);
            }
            const Victim* v = FindVictim(c.victim_id);
            if (!v) return Reject("no victim " + std::to_string(c.victim_id));
            if (v->status != VictimStatus::kConfirmed) {
              return Reject("victim " + std::to_string(c.victim_id) + " is " +
                            std::string(VictimStatusName(v->status)));
            }
            target_victim_ = c.victim_id;
            SetPhase(MissionPhase::kConverge, &r);
            return r;
          },
          [&](const BeginRescue& c) -> ApplyResult {
            if (phase != MissionPhase::kConverge || target_victim_ != c.victim_id) {
              return Reject("cannot begin rescue of victim " + std::to_string(c.victim_id) +
                            in_phase + " (target " + std::to_string(target_victim_) + ")");
            }
            if (c.lifter.empty()) return Reject("rescue without a lifter");
            Victim* v = nullptr;
            for (Victim& x : victims_) {
              if (x.id == c.victim_id) v = &x;
            }
            SWARMBOX_CHECK(v != nullptr);  // the target is always a known victim
            v->status = VictimStatus::kBeingRescued;
            v->rescuer = c.lifter;
            SetPhase(MissionPhase::kRescue, &r);
            r.events.push_back(
                VictimEvent(MissionEvent::Kind::kVictimStatus, phase_, applied_index_, *v));
            return r;
          },
          [&](const MarkRescued& c) -> ApplyResult {
            if (phase != MissionPhase::kRescue || target_victim_ != c.victim_id) {
              return Reject("victim " + std::to_string(c.victim_id) + " is not being rescued" +
                            in_phase);
            }
            Victim* v = nullptr;
            for (Victim& x : victims_) {
              if (x.id == c.victim_id) v = &x;
            }
            SWARMBOX_CHECK(v != nullptr);
            v->status = VictimStatus::kRescued;
            target_victim_ = 0;
            r.events.push_back(
                VictimEvent(MissionEvent::Kind::kVictimStatus, phase_, applied_index_, *v));
            SetPhase(MissionPhase::kSearch, &r);
            return r;
          },
          [&](const ReturnHome&) -> ApplyResult {
            if (!active) return Reject("cannot return home" + in_phase);
            target_victim_ = 0;
            SetPhase(MissionPhase::kReturn, &r);
            return r;
          },
          [&](const CompleteMission&) -> ApplyResult {
            if (phase != MissionPhase::kReturn) return Reject("cannot complete" + in_phase);
            SetPhase(MissionPhase::kComplete, &r);
            return r;
          },
      },
      command);
}

ApplyResult MissionState::ApplySighting(const ReportSighting& c) {
  if (c.reporter.empty()) return Reject("sighting without a reporter");
  if (!Finite(c.x_m) || !Finite(c.y_m) || !Finite(c.confidence) || c.confidence < 0 ||
      c.confidence > 1) {
    return Reject("sighting with a non-finite position or a confidence outside [0, 1]");
  }
  auto seq_it = last_seq_.find(c.reporter);
  if (c.seq == 0 || (seq_it != last_seq_.end() && c.seq <= seq_it->second)) {
    return Reject("duplicate or out-of-order sighting seq " + std::to_string(c.seq) + " from " +
                  c.reporter);
  }
  if (c.confidence < kMinConfidence) return Reject("sighting confidence below 0.5");
  last_seq_[c.reporter] = c.seq;
  ApplyResult r;
  r.accepted = true;
  if (Victim* v = NearVictim(c.x_m, c.y_m)) {
    bool known = false;
    for (const std::string& b : v->confirmed_by) known = known || b == c.reporter;
    if (!known) v->confirmed_by.push_back(c.reporter);
    return r;
  }
  if (c.confidence >= kHighConfidence) {
    AddVictim(c.x_m, c.y_m, {c.reporter}, &r);
    return r;
  }
  // The nearest pending sighting from another drone within the radius confirms.
  std::size_t match = pending_.size();
  double best_d = kConfirmRadiusM;
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    const Sighting& s = pending_[k];
    if (s.reporter == c.reporter) continue;
    const double d = Distance(s.x_m, s.y_m, c.x_m, c.y_m);
    if (d <= best_d) {
      best_d = d;
      match = k;
    }
  }
  if (match < pending_.size()) {
    const Sighting s = pending_[match];
    pending_.erase(pending_.begin() + static_cast<std::ptrdiff_t>(match));
    AddVictim((s.x_m + c.x_m) / 2, (s.y_m + c.y_m) / 2, {s.reporter, c.reporter}, &r);
    return r;
  }
  pending_.push_back(Sighting{c.reporter, c.seq, c.x_m, c.y_m, c.confidence});
  if (pending_.size() > kMaxPendingSightings) pending_.erase(pending_.begin());
  return r;
}

// --- snapshot ------------------------------------------------------------------------------------

Bytes MissionState::EncodeSnapshot() const {
  Bytes out;
  detail::ByteWriter w(&out);
  w.U8(kSnapshotVersion);
  w.Varint(applied_index_);
  w.U8(static_cast<std::uint8_t>(phase_));
  w.Varint(target_victim_);
  w.Varint(next_victim_id_);
  detail::WriteSectors(w, sectors_);
  w.Varint(last_seq_.size());
  for (const auto& [reporter, seq] : last_seq_) {
    w.Str(reporter);
    w.Varint(seq);
  }
  w.Varint(pending_.size());
  for (const Sighting& s : pending_) detail::WriteSighting(w, s);
  w.Varint(victims_.size());
  for (const Victim& v : victims_) {
    w.Varint(v.id);
    w.F64(v.x_m);
    w.F64(v.y_m);
    w.U8(static_cast<std::uint8_t>(v.status));
    w.Str(v.rescuer);
    w.Varint(v.confirmed_by.size());
    for (const std::string& b : v.confirmed_by) w.Str(b);
  }
  return out;
}

Result<MissionState> MissionState::DecodeSnapshot(std::span<const std::uint8_t> bytes) {
  detail::ByteReader r(bytes);
  auto fail = [](const std::string& what) {
    return Error(ErrorCode::kProtocol, what, "mission snapshot");
  };
  const std::uint8_t version = r.U8();
  if (!r.ok()) return fail("empty snapshot");
  if (version != kSnapshotVersion) {
    return fail("unsupported snapshot version " + std::to_string(version));
  }
  auto u32 = [&r](const char* what) {
    const std::uint64_t v = r.Varint();
    if (v > UINT32_MAX) r.Fail(std::string(what) + " out of range");
    return static_cast<std::uint32_t>(v);
  };
  MissionState m;
  m.applied_index_ = r.Varint();
  const std::uint8_t phase = r.U8();
  if (r.ok() && phase > static_cast<std::uint8_t>(MissionPhase::kComplete)) {
    return fail("invalid phase " + std::to_string(phase));
  }
  m.phase_ = static_cast<MissionPhase>(phase);
  m.target_victim_ = u32("target victim");
  m.next_victim_id_ = u32("next victim id");
  m.sectors_ = detail::ReadSectors(r);
  std::uint64_t n = r.Count(2, "reporter");
  for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
    std::string reporter = r.Str();
    m.last_seq_[reporter] = r.Varint();
  }
  n = r.Count(26, "sighting");
  for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
    m.pending_.push_back(detail::ReadSighting<Sighting>(r));
  }
  n = r.Count(20, "victim");
  for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
    Victim v;
    v.id = u32("victim id");
    v.x_m = r.F64();
    v.y_m = r.F64();
    const std::uint8_t status = r.U8();
    if (r.ok() && status > static_cast<std::uint8_t>(VictimStatus::kRescued)) {
      return fail("invalid victim status " + std::to_string(status));
    }
    v.status = static_cast<VictimStatus>(status);
    v.rescuer = r.Str();
    const std::uint64_t nb = r.Count(1, "confirmer");
    for (std::uint64_t b = 0; b < nb && r.ok(); ++b) v.confirmed_by.push_back(r.Str());
    m.victims_.push_back(std::move(v));
  }
  if (!r.ok()) return fail(r.error());
  if (!r.at_end()) return fail(std::to_string(r.remaining()) + " trailing bytes");
  return m;
}

}  // namespace swarmbox::raft
