#include "swarmbox/runner/trial_progress.hpp"

#include <cstdio>
#include <stdexcept>

#include "swarmbox/common/format.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/runner/end_matcher.hpp"

namespace swarmbox::runner {

namespace {

std::optional<std::int64_t> IntField(const LogfmtFields& fields, std::string_view key) {
  auto v = FindField(fields, key);
  if (!v) return std::nullopt;
  std::int64_t out = 0;
  try {
    std::size_t used = 0;
    out = std::stoll(std::string(*v), &used);
    if (used != v->size()) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return out;
}

std::optional<double> DoubleField(const LogfmtFields& fields, std::string_view key) {
  auto v = FindField(fields, key);
  if (!v) return std::nullopt;
  try {
    std::size_t used = 0;
    const double out = std::stod(std::string(*v), &used);
    if (used != v->size()) return std::nullopt;
    return out;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// What one contract event folds into the progress (the header's table).
void FoldClock(TrialProgress& p, const LogfmtFields& fields) {
  if (auto r = DoubleField(fields, "rtf")) p.rtf = *r;
}

void FoldLeaderElected(TrialProgress& p, const LogfmtFields& fields) {
  const auto term = IntField(fields, "term");
  const auto elected = FindField(fields, "leader");
  if (term && elected && *term > p.leader_term) {
    p.leader_term = *term;
    p.leader = *elected;
  }
}

void FoldMissionState(TrialProgress& p, const LogfmtFields& fields) {
  const auto index = IntField(fields, "index");
  const auto state = FindField(fields, "state");
  if (index && state && *index > p.stage_index && p.stage != "COMPLETE") {
    p.stage_index = *index;
    p.stage = std::string(*state);
  }
}

void FoldMissionComplete(TrialProgress& p, const LogfmtFields&) { p.stage = "COMPLETE"; }

void FoldSightingReported(TrialProgress& p, const LogfmtFields& fields) {
  if (!FindField(fields, "retry")) ++p.sightings;
}

// event=joining and event=joined.
void FoldJoining(TrialProgress& p, const LogfmtFields& fields) {
  JoiningProgress j;
  j.joined = IntField(fields, "joined").value_or(0);
  j.expected = IntField(fields, "expected").value_or(0);
  const auto missing = FindField(fields, "missing");
  if (missing && *missing != "-") j.missing = std::string(*missing);
  j.done = FindField(fields, "event") == "joined";
  j.lost = IntField(fields, "lost").value_or(0);
  j.wait_s = DoubleField(fields, "wait_s").value_or(0);
  if (!p.joining || !p.joining->done) p.joining = std::move(j);  // the start is over once joined
}

void FoldVictimConfirmed(TrialProgress& p, const LogfmtFields& fields) {
  if (auto id = IntField(fields, "id")) p.confirmed.insert(*id);
}

void FoldVictimStatus(TrialProgress& p, const LogfmtFields& fields) {
  const auto id = IntField(fields, "id");
  const auto status = FindField(fields, "status");
  if (id && status && *status == "rescued") p.rescued.insert(*id);
}

struct EventFold {
  std::string_view event;
  void (*fold)(TrialProgress&, const LogfmtFields&);
};

constexpr EventFold kEventFolds[] = {
    {"clock", FoldClock},
    {"leader_elected", FoldLeaderElected},
    {"mission_state", FoldMissionState},
    {"mission_complete", FoldMissionComplete},
    {"sighting_reported", FoldSightingReported},
    {"joining", FoldJoining},
    {"joined", FoldJoining},
    {"victim_confirmed", FoldVictimConfirmed},
    {"victim_status", FoldVictimStatus},
};

}  // namespace

void TrialProgress::OnLine(std::string_view component, std::string_view line) {
  (void)component;
  if (line.find("event=") == std::string_view::npos) {
    if (auto t = SimTimeOf(line); t && *t > sim_s) sim_s = *t;
    return;
  }
  const LogfmtFields fields = ParseLogfmt(line);
  if (auto t = DoubleField(fields, "t"); t && *t > sim_s) sim_s = *t;
  const auto event = FindField(fields, "event");
  if (!event) return;
  for (const EventFold& f : kEventFolds) {
    if (*event == f.event) f.fold(*this, fields);
  }
}

std::string RenderProgress(const TrialProgress& p, const ProgressFrame& frame) {
  std::string s = "sim " + FormatFixed(p.sim_s, 1) + "/" + FormatFixed(frame.timeout_sim_s, 1) + "s";
  if (p.rtf) s += "  rtf " + FormatFixed(*p.rtf, 2);
  s += "  wall " + FormatFixed(frame.wall_s, 1) + "s";
  if (p.joining && !p.joining->done) {
    s += "  joining " + std::to_string(p.joining->joined) + "/" + std::to_string(p.joining->expected);
  }
  if (!p.stage.empty()) s += "  stage " + p.stage;
  if (!p.leader.empty()) s += "  leader " + p.leader;
  if (p.sightings > 0 || !p.confirmed.empty() || !p.rescued.empty()) {
    s += "  victims sighted " + std::to_string(p.sightings) + " confirmed " +
         std::to_string(p.confirmed.size()) + " rescued " + std::to_string(p.rescued.size());
  }
  s += "  live " + std::to_string(frame.live) + "/" + std::to_string(frame.components);
  return s;
}

}  // namespace swarmbox::runner

namespace swarmbox::runner {

std::optional<std::string> NotJoinedNote(const TrialProgress& p) {
  if (!p.joining || p.joining->missing.empty()) return std::nullopt;
  const JoiningProgress& j = *p.joining;
  if (j.done && j.lost == 0) return std::nullopt;
  return "drones that did not join: " + j.missing + " (" + (j.done ? "lost at the start, " : "") + "joined " +
         std::to_string(j.joined) + "/" + std::to_string(j.expected) + ")";
}

std::optional<std::string> JoinedLine(const TrialProgress& p) {
  if (!p.joining || !p.joining->done) return std::nullopt;
  const JoiningProgress& j = *p.joining;
  std::string s = "joined " + std::to_string(j.joined) + "/" + std::to_string(j.expected) + " in " +
                  FormatFixed(j.wait_s, 1) + " s";
  if (j.lost > 0) s += "; lost at the start: " + j.missing;
  return s;
}

}  // namespace swarmbox::runner
