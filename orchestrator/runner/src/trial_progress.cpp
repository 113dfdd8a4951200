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
  if (*event == "clock") {
    if (auto r = DoubleField(fields, "rtf")) rtf = *r;
  } else if (*event == "leader_elected") {
    const auto term = IntField(fields, "term");
    const auto elected = FindField(fields, "leader");
    if (term && elected && *term > leader_term) {
      leader_term = *term;
      leader = *elected;
    }
  } else if (*event == "mission_state") {
    const auto index = IntField(fields, "index");
    const auto state = FindField(fields, "state");
    if (index && state && *index > stage_index && stage != "COMPLETE") {
      stage_index = *index;
      stage = std::string(*state);
    }
  } else if (*event == "mission_complete") {
    stage = "COMPLETE";
  } else if (*event == "sighting_reported") {
    if (!FindField(fields, "retry")) ++sightings;
  } else if (*event == "joining" || *event == "joined") {
    JoiningProgress j;
    j.joined = IntField(fields, "joined").value_or(0);
    j.expected = IntField(fields, "expected").value_or(0);
    const auto missing = FindField(fields, "missing");
    if (missing && *missing != "-") j.missing = std::string(*missing);
    j.done = *event == "joined";
    j.lost = IntField(fields, "lost").value_or(0);
    j.wait_s = DoubleField(fields, "wait_s").value_or(0);
    if (!joining || !joining->done) joining = std::move(j);  // the start is over once joined
  } else if (*event == "victim_confirmed") {
    if (auto id = IntField(fields, "id")) confirmed.insert(*id);
  } else if (*event == "victim_status") {
    const auto id = IntField(fields, "id");
    const auto status = FindField(fields, "status");
    if (id && status && *status == "rescued") rescued.insert(*id);
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
