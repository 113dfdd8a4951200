// Which brain flies the drone (agent/app/README.md "Which brain flies"), from the command line, validated
// before anything joins the bus (bad input: kInvalidArgument, the agent exits 2):
//   --brain builtin   the built-in logic: --mission plan|sar as before (the default)
//   --brain library   --brain-library PATH --brain-name NAME: a SWARMBOX_BRAIN in a shared library
//   --brain external  a brain in its own process on the offboard topics (external_brain.hpp)
// with --brain-args JSON (a JSON object: Context::args), --brain-rate-hz, the offboard failsafe's
// --offboard-timeout-ms / --offboard-hold-ms (simulated) and an external brain's wall-clock
// liveness bounds --brain-wait-ms / --brain-start-ms.
//
//   BrainOptions b;  b.kind = BrainKind::kLibrary;  b.library_path = "librv.so";  b.name = "rendezvous";
//   if (Status s = ValidateBrainOptions(b, mission_given, plan_given); !s) { print; exit(2); }
//   Result<int> steps = BrainPeriodSteps(b, 0.004);     // 250 Hz lockstep: 1 (library), 5 (external)
#pragma once

#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"

namespace swarmbox::agent {

enum class BrainKind { kBuiltin, kLibrary, kExternal };
std::string_view BrainKindName(BrainKind kind);  // "builtin", "library", "external"
// "builtin" | "library" | "external"; kInvalidArgument naming the accepted values otherwise.
Result<BrainKind> ParseBrainKind(std::string_view text);

struct BrainOptions {
  BrainKind kind = BrainKind::kBuiltin;
  std::string library_path;        // --brain-library (library)
  std::string name;                // --brain-name (library: the SWARMBOX_BRAIN name)
  std::string args_json = "{}";    // --brain-args: a JSON object
  double rate_hz = 0.0;            // --brain-rate-hz; 0: the default (every step; external: 50 Hz)
  int offboard_timeout_ms = 1000;  // --offboard-timeout-ms, simulated (PX4 COM_OF_LOSS_T 1.0 s)
  int offboard_hold_ms = 5000;     // --offboard-hold-ms, simulated hold before landing
  int wait_ms = 3000;              // --brain-wait-ms, wall clock (external)
  int start_ms = 30000;            // --brain-start-ms, wall clock (external, the first answer)
  int neighbours = 32;             // --brain-neighbours: Input::neighbours holds at most this many (the nearest), > 0
};

inline constexpr double kExternalDefaultRateHz = 50.0;

// Checks the combination: library needs a path and a name; name and path only with library;
// the builtin path is chosen by --mission (so `mission_given`/`plan_given`, i.e. --mission or
// --plan on the command line, need --brain builtin); timings positive (hold >= 0).
Status ValidateBrainOptions(const BrainOptions& options, bool mission_given, bool plan_given);

// The brain period in lockstep steps of `control_dt_s`: round(1 / (rate_hz * dt)), which must be
// a whole number >= 1 (kInvalidArgument naming the rates that are: 250, 125, 50, ... at 4 ms),
// and shorter than the offboard timeout (else the failsafe would fire between two periods).
Result<int> BrainPeriodSteps(const BrainOptions& options, double control_dt_s);

}  // namespace swarmbox::agent
