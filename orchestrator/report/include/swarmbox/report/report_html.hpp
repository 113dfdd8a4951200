// report.html: a self-contained page (inline CSS and SVG, no scripts, no external files except
// each trial's own trajectories.png and plots.html, linked relative to the experiment folder). Pure.
//
//   1. totals: trials per outcome;
//   2. per factor, outcome counts per level;
//   3. per metric with at least one value, per factor, a box plot per level (Tukey: box = quartiles,
//      whiskers to the furthest points within 1.5 IQR, points beyond drawn as outliers; n under
//      each box);
//   4. a table of every trial (levels, seed, host, outcome, reason, times) linking its folder,
//      logs, plots.html (its quantities over time, trial_plots.hpp) and trajectories.png.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/report/trial_record.hpp"

namespace swarmbox::report {

struct BoxStats {
  std::size_t n = 0;
  double min = 0, q1 = 0, median = 0, q3 = 0, max = 0;
  double whisker_low = 0, whisker_high = 0;  // furthest points within 1.5 IQR of the box
  std::vector<double> outliers;
};

// Quartiles by linear interpolation between order statistics (type 7, as R and numpy default).
// n == 0 gives all zeros.
BoxStats ComputeBoxStats(std::vector<double> values);

// HTML escaping of text and attribute values.
std::string HtmlEscape(std::string_view text);

// One box plot of the page: a metric's distribution per level of one factor, as inline SVG.
struct ReportPlot {
  std::string metric;
  std::string factor;
  std::string svg;
};

// Every plot of the page, in page order (metric by metric, factors in order); metrics no trial
// reported are left out.
std::vector<ReportPlot> ReportPlots(const std::vector<std::string>& factors,
                                    const std::vector<TrialRecord>& records);

// `<metric>_by_<factor>.svg`, characters outside [A-Za-z0-9_-] replaced by '_'.
std::string PlotFileName(const ReportPlot& plot);

// The plot as a standalone SVG file (its own style and title), as written to plots/ next to
// report.html so that other documents (a README) can show it.
std::string StandalonePlotSvg(const ReportPlot& plot);

std::string ReportHtml(std::string_view title, const std::vector<std::string>& factors,
                       const std::vector<TrialRecord>& records);

}  // namespace swarmbox::report
