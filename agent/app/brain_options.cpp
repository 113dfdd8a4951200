#include "brain_options.hpp"

#include <cmath>
#include <cstdio>

namespace swarmbox::agent {

std::string_view BrainKindName(BrainKind kind) {
  switch (kind) {
    case BrainKind::kLibrary: return "library";
    case BrainKind::kExternal: return "external";
    case BrainKind::kBuiltin: break;
  }
  return "builtin";
}

Result<BrainKind> ParseBrainKind(std::string_view text) {
  if (text == "builtin") return BrainKind::kBuiltin;
  if (text == "library") return BrainKind::kLibrary;
  if (text == "external") return BrainKind::kExternal;
  return Error(ErrorCode::kInvalidArgument, "--brain '" + std::string(text) + "': expected builtin, library or external");
}

Status ValidateBrainOptions(const BrainOptions& o, bool mission_given, bool plan_given) {
  const auto bad = [](const std::string& what) { return Error(ErrorCode::kInvalidArgument, what); };
  if (o.kind == BrainKind::kLibrary) {
    if (o.library_path.empty()) return bad("--brain library needs --brain-library PATH (the .so)");
    if (o.name.empty()) return bad("--brain library needs --brain-name NAME (the SWARMBOX_BRAIN name in it)");
  } else {
    if (!o.library_path.empty()) return bad("--brain-library is for --brain library");
    if (!o.name.empty()) return bad("--brain-name is for --brain library");
  }
  if (o.kind != BrainKind::kBuiltin) {
    if (mission_given) return bad("--mission is for --brain builtin (the brain decides what to fly)");
    if (plan_given) return bad("--plan is for --brain builtin (the brain decides what to fly)");
  }
  if (o.rate_hz < 0.0 || !std::isfinite(o.rate_hz)) return bad("--brain-rate-hz must be > 0");
  if (o.offboard_timeout_ms <= 0) return bad("--offboard-timeout-ms must be > 0");
  if (o.offboard_hold_ms < 0) return bad("--offboard-hold-ms must be >= 0");
  if (o.neighbours <= 0) return bad("--brain-neighbours must be > 0");
  if (o.wait_ms <= 0) return bad("--brain-wait-ms must be > 0");
  if (o.start_ms <= 0) return bad("--brain-start-ms must be > 0");
  return Ok{};
}

Result<int> BrainPeriodSteps(const BrainOptions& o, double control_dt_s) {
  const double steps_per_s = 1.0 / control_dt_s;
  const double hz = o.rate_hz > 0.0 ? o.rate_hz : (o.kind == BrainKind::kExternal ? kExternalDefaultRateHz : steps_per_s);
  const double steps = steps_per_s / hz;
  const double whole = std::round(steps);
  if (whole < 1.0 || std::abs(steps - whole) > 1e-6 * steps) {
    std::string ok;
    const long n = std::lround(steps_per_s);
    for (long k = 1; k <= n && ok.size() < 60; ++k) {
      if (n % k == 0) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%s%g", ok.empty() ? "" : ", ", steps_per_s / static_cast<double>(k));
        ok += buf;
      }
    }
    char what[64];
    std::snprintf(what, sizeof what, "%g", hz);
    return Error(ErrorCode::kInvalidArgument, "--brain-rate-hz " + std::string(what) +
                                                  ": the brain runs every whole number of lockstep steps (" +
                                                  std::to_string(n) + " per second): e.g. " + ok);
  }
  const double period_ms = whole * control_dt_s * 1e3;
  if (period_ms >= o.offboard_timeout_ms) {
    char what[96];
    std::snprintf(what, sizeof what, "the brain period (%g ms) must be shorter than --offboard-timeout-ms (%d)", period_ms,
                  o.offboard_timeout_ms);
    return Error(ErrorCode::kInvalidArgument, std::string(what) + ": a brain answering at every period would be lost between two");
  }
  return static_cast<int>(whole);
}

}  // namespace swarmbox::agent
