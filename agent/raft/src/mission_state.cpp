#include "swarmbox/raft/mission_state.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "swarmbox/raft/detail/byte_io.hpp"
#include "swarmbox/raft/detail/mission_io.hpp"

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

const Candidate* MissionState::FindCandidate(std::uint32_t id) const {
  for (const Candidate& c : candidates_) {
    if (c.id == id) return &c;
  }
  return nullptr;
}

Candidate* MissionState::MutableCandidate(std::uint32_t id) {
  for (Candidate& c : candidates_) {
    if (c.id == id) return &c;
  }
  return nullptr;
}

const Candidate* MissionState::CandidateAt(double x_m, double y_m) const {
  const Candidate* best = nullptr;
  double best_d = kConfirmRadiusM;
  for (const Candidate& c : candidates_) {
    if (c.status == CandidateStatus::kConfirmed) continue;  // its victim takes the sightings
    const double d = Distance(c.x_m, c.y_m, x_m, y_m);
    if (d <= best_d) {
      best = &c;
      best_d = d;
    }
  }
  return best;
}

void MissionState::AddView(Candidate& c, SightingView v) {
  // The revisit is done once the drone sent there reports what it saw (a view or a miss).
  if (!c.revisit_drone.empty() && v.reporter == c.revisit_drone && v.t_s >= c.revisit_t_s) {
    c.revisit_drone.clear();
    ++c.revisits;
  }
  c.views.push_back(std::move(v));
  // The position comes from the closest looks only: a geolocation's error grows with the camera's
  // height, and a detector that fires from 30 m on a heap beside the person would otherwise pull
  // the drop point metres off (see kCloseLookBand).
  double lowest = std::numeric_limits<double>::infinity();
  for (const SightingView& e : c.views) {
    if (e.detected) lowest = std::min(lowest, e.viewer_height_m);
  }
  const double band = lowest + (kCloseLookBand - 1) * std::max(lowest, 0.0);
  double w = 0, x = 0, y = 0;
  for (const SightingView& e : c.views) {
    if (!e.detected || e.viewer_height_m > band) continue;
    w += e.confidence;
    x += e.confidence * e.x_m;
    y += e.confidence * e.y_m;
  }
  if (w > 0) {
    c.x_m = x / w;
    c.y_m = y / w;
  }
}

std::string MissionState::CheckSeq(const std::string& reporter, std::uint64_t seq) const {
  auto it = last_seq_.find(reporter);
  if (seq == 0 || (it != last_seq_.end() && seq <= it->second)) {
    return "duplicate or out-of-order sighting seq " + std::to_string(seq) + " from " + reporter;
  }
  return "";
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

ApplyResult MissionState::AcceptedEntering(MissionPhase phase) {
  ApplyResult r = Accepted();
  SetPhase(phase, &r);
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
  return std::visit([this](const auto& c) { return Handle(c); }, command);
}

// --- one handler per command: each checks the phase, then the command, then applies it -----------

bool MissionState::Active() const {
  return phase_ == MissionPhase::kSearch || phase_ == MissionPhase::kConverge ||
         phase_ == MissionPhase::kRescue;
}

std::string MissionState::InPhase() const {
  return std::string(" in phase ") + std::string(PhaseName(phase_));
}

ApplyResult MissionState::Accepted() {
  ApplyResult r;
  r.accepted = true;
  return r;
}

Victim& MissionState::MutableVictim(std::uint32_t id) {
  Victim* v = nullptr;
  for (Victim& x : victims_) {
    if (x.id == id) v = &x;
  }
  SWARMBOX_CHECK(v != nullptr);  // the target is always a known victim
  return *v;
}

ApplyResult MissionState::Handle(const StartSearch&) {
  if (phase_ != MissionPhase::kIdle) return Reject("cannot start search" + InPhase());
  return AcceptedEntering(MissionPhase::kSearch);
}

ApplyResult MissionState::Handle(const AssignSectors& c) {
  if (phase_ == MissionPhase::kComplete) return Reject("cannot assign sectors" + InPhase());
  for (const Sector& s : c.sectors) {
    if (s.drone.empty()) return Reject("sector without a drone");
    if (!Finite(s.x_min_m) || !Finite(s.y_min_m) || !Finite(s.x_max_m) || !Finite(s.y_max_m) ||
        s.x_min_m >= s.x_max_m || s.y_min_m >= s.y_max_m) {
      return Reject("sector of " + s.drone + " is not a rectangle with min < max");
    }
  }
  sectors_ = c.sectors;
  return Accepted();
}

ApplyResult MissionState::Handle(const ReportSighting& c) {
  if (!Active()) return Reject("sighting ignored" + InPhase());
  return ApplySighting(c);
}

ApplyResult MissionState::Handle(const ConfirmVictim& c) {
  if (!Active()) return Reject("cannot confirm a victim" + InPhase());
  if (!Finite(c.x_m) || !Finite(c.y_m)) return Reject("victim position is not finite");
  if (Victim* v = NearVictim(c.x_m, c.y_m)) {
    return Reject("victim " + std::to_string(v->id) + " is already confirmed there");
  }
  ApplyResult r = Accepted();
  AddVictim(c.x_m, c.y_m, {c.by}, &r);
  return r;
}

ApplyResult MissionState::Handle(const ConvergeOn& c) {
  if (phase_ != MissionPhase::kSearch && phase_ != MissionPhase::kConverge) {
    return Reject("cannot converge" + InPhase());
  }
  const Victim* v = FindVictim(c.victim_id);
  if (!v) return Reject("no victim " + std::to_string(c.victim_id));
  if (v->status != VictimStatus::kConfirmed) {
    return Reject("victim " + std::to_string(c.victim_id) + " is " +
                  std::string(VictimStatusName(v->status)));
  }
  target_victim_ = c.victim_id;
  return AcceptedEntering(MissionPhase::kConverge);
}

ApplyResult MissionState::Handle(const BeginRescue& c) {
  if (phase_ != MissionPhase::kConverge || target_victim_ != c.victim_id) {
    return Reject("cannot begin rescue of victim " + std::to_string(c.victim_id) + InPhase() +
                  " (target " + std::to_string(target_victim_) + ")");
  }
  if (c.lifter.empty()) return Reject("rescue without a lifter");
  Victim& v = MutableVictim(c.victim_id);
  v.status = VictimStatus::kBeingRescued;
  v.rescuer = c.lifter;
  ApplyResult r = AcceptedEntering(MissionPhase::kRescue);
  r.events.push_back(VictimEvent(MissionEvent::Kind::kVictimStatus, phase_, applied_index_, v));
  return r;
}

ApplyResult MissionState::Handle(const MarkRescued& c) {
  if (phase_ != MissionPhase::kRescue || target_victim_ != c.victim_id) {
    return Reject("victim " + std::to_string(c.victim_id) + " is not being rescued" + InPhase());
  }
  Victim& v = MutableVictim(c.victim_id);
  v.status = VictimStatus::kRescued;
  target_victim_ = 0;
  ApplyResult r = Accepted();
  r.events.push_back(VictimEvent(MissionEvent::Kind::kVictimStatus, phase_, applied_index_, v));
  SetPhase(MissionPhase::kSearch, &r);
  return r;
}

ApplyResult MissionState::Handle(const ReturnHome&) {
  if (!Active()) return Reject("cannot return home" + InPhase());
  target_victim_ = 0;
  return AcceptedEntering(MissionPhase::kReturn);
}

ApplyResult MissionState::Handle(const CompleteMission&) {
  if (phase_ != MissionPhase::kReturn) return Reject("cannot complete" + InPhase());
  return AcceptedEntering(MissionPhase::kComplete);
}

ApplyResult MissionState::Handle(const ReportMiss& c) {
  if (!Active()) return Reject("miss ignored" + InPhase());
  return ApplyMiss(c);
}

ApplyResult MissionState::Handle(const RequestRevisit& c) {
  if (!Active()) return Reject("cannot request a revisit" + InPhase());
  if (c.drone.empty() || !Finite(c.t_s)) return Reject("revisit without a drone or a time");
  Candidate* k = MutableCandidate(c.candidate);
  if (k == nullptr || k->status != CandidateStatus::kPending) {
    return Reject("no pending candidate " + std::to_string(c.candidate));
  }
  if (!k->revisit_drone.empty()) ++k->revisits;  // the one under way is abandoned: it counts
  k->revisit_drone = c.drone;
  k->revisit_t_s = c.t_s;
  return Accepted();
}

ApplyResult MissionState::Handle(const ConfirmSighting& c) {
  if (!Active()) return Reject("cannot confirm a sighting" + InPhase());
  if (!Finite(c.belief) || c.belief < 0 || c.belief > 1) return Reject("belief outside [0, 1]");
  Candidate* k = MutableCandidate(c.candidate);
  if (k == nullptr || k->status == CandidateStatus::kConfirmed) {
    return Reject("no undecided candidate " + std::to_string(c.candidate));
  }
  if (Victim* v = NearVictim(k->x_m, k->y_m)) {
    return Reject("victim " + std::to_string(v->id) + " is already confirmed there");
  }
  std::vector<std::string> by;
  for (const SightingView& e : k->views) {
    if (e.detected && std::find(by.begin(), by.end(), e.reporter) == by.end()) by.push_back(e.reporter);
  }
  k->status = CandidateStatus::kConfirmed;
  k->revisit_drone.clear();
  k->belief = c.belief;
  ApplyResult r = Accepted();
  k->victim_id = AddVictim(k->x_m, k->y_m, std::move(by), &r).id;
  return r;
}

ApplyResult MissionState::Handle(const RejectSighting& c) {
  if (!Active()) return Reject("cannot reject a sighting" + InPhase());
  if (!Finite(c.belief) || c.belief < 0 || c.belief > 1) return Reject("belief outside [0, 1]");
  Candidate* k = MutableCandidate(c.candidate);
  if (k == nullptr || k->status != CandidateStatus::kPending) {
    return Reject("no pending candidate " + std::to_string(c.candidate));
  }
  k->status = CandidateStatus::kRejected;
  k->revisit_drone.clear();
  k->belief = c.belief;
  return Accepted();
}

ApplyResult MissionState::ApplySighting(const ReportSighting& c) {
  if (c.reporter.empty()) return Reject("sighting without a reporter");
  if (!Finite(c.x_m) || !Finite(c.y_m) || !Finite(c.confidence) || c.confidence < 0 ||
      c.confidence > 1 || !Finite(c.viewer_x_m) || !Finite(c.viewer_y_m) ||
      !Finite(c.viewer_height_m) || !Finite(c.t_s)) {
    return Reject("sighting with a non-finite position or a confidence outside [0, 1]");
  }
  if (std::string why = CheckSeq(c.reporter, c.seq); !why.empty()) return Reject(std::move(why));
  if (c.confidence < kMinConfidence) return Reject("sighting confidence below 0.5");
  ApplyResult r;
  r.accepted = true;
  if (Victim* v = NearVictim(c.x_m, c.y_m)) {
    last_seq_[c.reporter] = c.seq;
    bool known = false;
    for (const std::string& b : v->confirmed_by) known = known || b == c.reporter;
    if (!known) v->confirmed_by.push_back(c.reporter);
    return r;
  }
  SightingView view{c.reporter, c.seq, c.x_m, c.y_m, c.confidence, c.viewer_x_m, c.viewer_y_m,
                    c.viewer_height_m, c.t_s, true};
  const Candidate* near = CandidateAt(c.x_m, c.y_m);
  Candidate* k = near != nullptr ? MutableCandidate(near->id) : nullptr;
  if (k != nullptr && k->views.size() >= kMaxViews) {
    return Reject("candidate " + std::to_string(k->id) + " holds " + std::to_string(kMaxViews) + " views");
  }
  last_seq_[c.reporter] = c.seq;
  if (k == nullptr) k = &NewCandidate(c.x_m, c.y_m);
  AddView(*k, std::move(view));
  return r;
}

Candidate& MissionState::NewCandidate(double x_m, double y_m) {
  if (candidates_.size() >= kMaxCandidates) {
    auto old = std::find_if(candidates_.begin(), candidates_.end(),
                            [](const Candidate& x) { return x.status != CandidateStatus::kPending; });
    candidates_.erase(old != candidates_.end() ? old : candidates_.begin());
  }
  Candidate fresh;
  fresh.id = next_candidate_id_++;
  fresh.x_m = x_m;
  fresh.y_m = y_m;
  candidates_.push_back(std::move(fresh));
  return candidates_.back();
}

ApplyResult MissionState::ApplyMiss(const ReportMiss& c) {
  if (c.reporter.empty()) return Reject("miss without a reporter");
  if (!Finite(c.viewer_x_m) || !Finite(c.viewer_y_m) || !Finite(c.viewer_height_m) || !Finite(c.t_s)) {
    return Reject("miss with a non-finite viewpoint");
  }
  if (std::string why = CheckSeq(c.reporter, c.seq); !why.empty()) return Reject(std::move(why));
  Candidate* k = MutableCandidate(c.candidate);
  if (k == nullptr || k->status == CandidateStatus::kConfirmed) {
    return Reject("no undecided candidate " + std::to_string(c.candidate));
  }
  if (k->views.size() >= kMaxViews) {
    return Reject("candidate " + std::to_string(k->id) + " holds " + std::to_string(kMaxViews) + " views");
  }
  last_seq_[c.reporter] = c.seq;
  AddView(*k, SightingView{c.reporter, c.seq, k->x_m, k->y_m, 0.0, c.viewer_x_m, c.viewer_y_m,
                           c.viewer_height_m, c.t_s, false});
  ApplyResult r;
  r.accepted = true;
  return r;
}

// --- snapshot ------------------------------------------------------------------------------------

namespace {

// A mission record (Candidate, Victim) starts with its id, position and status.
template <class Record>
void WriteRecordHead(detail::ByteWriter& w, const Record& rec) {
  w.Varint(rec.id);
  w.F64(rec.x_m);
  w.F64(rec.y_m);
  w.U8(static_cast<std::uint8_t>(rec.status));
}

void WriteCandidate(detail::ByteWriter& w, const Candidate& c) {
  WriteRecordHead(w, c);
  w.Str(c.revisit_drone);
  w.F64(c.revisit_t_s);
  w.Varint(c.revisits);
  w.Varint(c.victim_id);
  w.F64(c.belief);
  w.Varint(c.views.size());
  for (const SightingView& v : c.views) {
    detail::WriteSighting(w, v);
    w.U8(v.detected ? 1 : 0);
  }
}

void WriteVictim(detail::ByteWriter& w, const Victim& v) {
  WriteRecordHead(w, v);
  w.Str(v.rescuer);
  w.Varint(v.confirmed_by.size());
  for (const std::string& b : v.confirmed_by) w.Str(b);
}

// A varint that must fit 32 bits; a larger one latches "<what> out of range" in `r`.
std::uint32_t ReadU32(detail::ByteReader& r, const char* what) {
  const std::uint64_t v = r.Varint();
  if (v > UINT32_MAX) r.Fail(std::string(what) + " out of range");
  return static_cast<std::uint32_t>(v);
}

// An enum byte no larger than `last`; a larger one sets *invalid to "invalid <what> <byte>".
template <class E>
E ReadEnum(detail::ByteReader& r, E last, const char* what, std::string* invalid) {
  const std::uint8_t v = r.U8();
  if (r.ok() && v > static_cast<std::uint8_t>(last)) {
    *invalid = std::string("invalid ") + what + " " + std::to_string(v);
  }
  return static_cast<E>(v);
}

// WriteRecordHead's fields into *rec, the status no larger than `last_status`. False when the status
// is invalid (*invalid is then set): the rest of the record must not be read.
template <class Record>
bool ReadRecordHead(detail::ByteReader& r, Record* rec, decltype(Record::status) last_status,
                    const char* id_what, const char* status_what, std::string* invalid) {
  rec->id = ReadU32(r, id_what);
  rec->x_m = r.F64();
  rec->y_m = r.F64();
  rec->status = ReadEnum(r, last_status, status_what, invalid);
  return invalid->empty();
}

// Stops after the status when it is invalid (*invalid is then set).
Candidate ReadCandidate(detail::ByteReader& r, std::string* invalid) {
  Candidate c;
  if (!ReadRecordHead(r, &c, CandidateStatus::kRejected, "candidate id", "candidate status", invalid)) {
    return c;
  }
  c.revisit_drone = r.Str();
  c.revisit_t_s = r.F64();
  c.revisits = ReadU32(r, "revisits");
  c.victim_id = ReadU32(r, "candidate victim");
  c.belief = r.F64();
  const std::uint64_t nv = r.Count(59, "view");
  for (std::uint64_t j = 0; j < nv && r.ok(); ++j) {
    SightingView v = detail::ReadSighting<SightingView>(r);
    v.detected = r.U8() != 0;
    c.views.push_back(std::move(v));
  }
  return c;
}

// Stops after the status when it is invalid (*invalid is then set).
Victim ReadVictim(detail::ByteReader& r, std::string* invalid) {
  Victim v;
  if (!ReadRecordHead(r, &v, VictimStatus::kRescued, "victim id", "victim status", invalid)) return v;
  v.rescuer = r.Str();
  const std::uint64_t nb = r.Count(1, "confirmer");
  for (std::uint64_t b = 0; b < nb && r.ok(); ++b) v.confirmed_by.push_back(r.Str());
  return v;
}

}  // namespace

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
  w.Varint(next_candidate_id_);
  w.Varint(candidates_.size());
  for (const Candidate& c : candidates_) WriteCandidate(w, c);
  w.Varint(victims_.size());
  for (const Victim& v : victims_) WriteVictim(w, v);
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
  MissionState m;
  std::string invalid;  // an enum byte out of range (ReadEnum)
  m.applied_index_ = r.Varint();
  m.phase_ = ReadEnum(r, MissionPhase::kComplete, "phase", &invalid);
  if (!invalid.empty()) return fail(invalid);
  m.target_victim_ = ReadU32(r, "target victim");
  m.next_victim_id_ = ReadU32(r, "next victim id");
  m.sectors_ = detail::ReadSectors(r);
  std::uint64_t n = r.Count(2, "reporter");
  for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
    std::string reporter = r.Str();
    m.last_seq_[reporter] = r.Varint();
  }
  m.next_candidate_id_ = ReadU32(r, "next candidate id");
  n = r.Count(38, "candidate");
  for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
    Candidate c = ReadCandidate(r, &invalid);
    if (!invalid.empty()) return fail(invalid);
    m.candidates_.push_back(std::move(c));
  }
  n = r.Count(20, "victim");
  for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
    Victim v = ReadVictim(r, &invalid);
    if (!invalid.empty()) return fail(invalid);
    m.victims_.push_back(std::move(v));
  }
  if (!r.ok()) return fail(r.error());
  if (!r.at_end()) return fail(std::to_string(r.remaining()) + " trailing bytes");
  return m;
}

}  // namespace swarmbox::raft
