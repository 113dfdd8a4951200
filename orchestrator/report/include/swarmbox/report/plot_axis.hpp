// The value axis of a report plot: where it starts and ends and which ticks it shows. Pure.
//
// An axis starts at the metric's natural bound when it has one (0 for counts and rates: an all-zero
// collisions column draws 0..1, not -0.55..0.55), never below 0 for a quantity that cannot be
// negative, never above a rate's 1, and its ticks are round: a step of 1, 2 or 5 times a power of
// ten (counts: whole steps only), the ends on a tick.
//
//   PlotAxis a = ChooseAxis(0.0079, 0.1169, AxisKindOf("radio_loss"));
//   // a.lo 0, a.hi 0.12, a.step 0.02, a.Ticks() 0, 0.02, ..., 0.12
#pragma once

#include <optional>
#include <string_view>
#include <vector>

namespace swarmbox::report {

struct AxisKind {
  bool from_zero = false;       // a count or rate: the axis starts at 0
  bool integer = false;         // a count: steps of at least 1
  bool non_negative = true;     // the axis never goes below 0
  std::optional<double> max;    // an upper bound the axis never passes (1 for a rate)
};

// What the axis of a results.csv metric (or wall_s, sim_s) looks like.
AxisKind AxisKindOf(std::string_view metric);

// The smallest step of the 1-2-5 series (1, 2, 5, 10, 20, ...; 0.5, 0.2, 0.1, ...) >= `raw` (> 0).
double NiceStep(double raw);

struct PlotAxis {
  double lo = 0;
  double hi = 1;
  double step = 1;
  // lo, lo + step, ..., hi (each rounded to the step, so 0.3 is not 0.30000000000000004).
  std::vector<double> Ticks() const;
};

// An axis holding [data_min, data_max] with at most `max_ticks` ticks (>= 2).
PlotAxis ChooseAxis(double data_min, double data_max, const AxisKind& kind, int max_ticks = 6);

}  // namespace swarmbox::report
