// plots.html: one trial's quantities over simulated time as small multiples, one self-contained
// page (inline CSS and SVG, no script, no external resource but the trial's own
// trajectories.png beside it). Pure: TrialSeries in, text out (WriteTrialPlots in
// trial_record.hpp reads the folder and writes the file).
//
// Panels, all on the same time axis (0 .. the trial's last simulated time):
//   altitude, speed, nearest neighbour (truth.csv); radio loss and RTT (event=link); Raft term
//   (a step line) and the leader each node followed (a state band per node); battery;
//   mission stage (a state band per node); flocking order / safety / union (the leader's
//   event=flock_metrics). A panel whose events the trial did not log says so instead of drawing
//   empty axes.
// Line panels draw one line per drone up to kMaxLines drones (one colour per drone on the whole
// page, legend on top); above that, the swarm's envelope over time (min..max band, median line,
// in time bins), so that a 100-drone trial's page stays readable and small. State bands have one
// row per node (thinner as nodes are added) and their own legend.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/report/trial_series.hpp"

namespace swarmbox::report {

inline constexpr std::size_t kMaxLines = 10;  // more series than this: the envelope

// The envelope of many series over time: `bins` equal time bins over [0, t_end_s], each with the
// values of the points in it; `step` series (a value held until the next point, the Raft term)
// give each bin their value at its end instead. A bin with no value is left out. Pure, for the
// chart and its test.
struct EnvelopeBin {
  double t_s = 0;  // the bin's centre
  double min = 0, median = 0, max = 0;
};
std::vector<EnvelopeBin> Envelope(const std::vector<Series>& series, double t_end_s, int bins,
                                  bool step = false);

struct TrialPlotsPage {
  std::string title;              // e.g. "sar-search (run 20261125-225940-62dd)"
  std::string summary;            // one line under the title (outcome, reason), may be empty
  bool has_trajectories = false;  // show trajectories.png beside the page
};

// The panels' SVGs in page order with their captions (for tests and the page).
struct TrialPanel {
  std::string caption;  // "altitude [m]"
  std::string svg;      // "" when the trial has no data for it
  std::string missing;  // why there is no chart ("no event=battery in the logs")
};
std::vector<TrialPanel> TrialPanels(const TrialSeries& series);

std::string TrialPlotsHtml(const TrialPlotsPage& page, const TrialSeries& series);

}  // namespace swarmbox::report
