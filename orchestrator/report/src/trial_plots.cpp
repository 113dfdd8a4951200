#include "swarmbox/report/trial_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "swarmbox/report/plot_axis.hpp"
#include "swarmbox/report/report_html.hpp"
#include "swarmbox/report/results_csv.hpp"

namespace swarmbox::report {

namespace {

// Tableau 10: distinct on white, in print and for most colour-blind readers.
constexpr const char* kPalette[] = {"#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f",
                                    "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac"};
constexpr std::size_t kPaletteSize = sizeof kPalette / sizeof kPalette[0];

constexpr double kW = 460, kH = 190, kLeft = 52, kRight = 12, kTop = 10, kBottom = 30;
constexpr int kEnvelopeBins = 150;

std::string F1(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string F3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// Where things go on a panel.
struct Frame {
  PlotAxis t;
  PlotAxis y;
  double x(double t_s) const { return kLeft + (t_s - t.lo) / (t.hi - t.lo) * (kW - kLeft - kRight); }
  double yv(double v) const {
    const double c = std::clamp(v, y.lo, y.hi);
    return kTop + (y.hi - c) / (y.hi - y.lo) * (kH - kTop - kBottom);
  }
};

PlotAxis TimeAxis(double t_end_s) {
  AxisKind k;
  k.from_zero = true;
  return ChooseAxis(0, std::max(t_end_s, 1.0), k, 7);
}

// Axes, grid and tick labels; the time label under the last tick.
std::string Axes(const Frame& f, bool time_ticks) {
  std::string s = "<svg width='" + F1(kW) + "' height='" + F1(kH) + "' class='ts'>";
  for (double v : f.y.Ticks()) {
    s += "<line x1='" + F1(kLeft) + "' x2='" + F1(kW - kRight) + "' y1='" + F1(f.yv(v)) + "' y2='" +
         F1(f.yv(v)) + "' class='grid'/><text x='" + F1(kLeft - 5) + "' y='" + F1(f.yv(v) + 4) +
         "' text-anchor='end'>" + CsvNumber(v) + "</text>";
  }
  if (time_ticks) {
    for (double v : f.t.Ticks()) {
      s += "<line x1='" + F1(f.x(v)) + "' x2='" + F1(f.x(v)) + "' y1='" + F1(kTop) + "' y2='" +
           F1(kH - kBottom) + "' class='grid'/><text x='" + F1(f.x(v)) + "' y='" + F1(kH - kBottom + 14) +
           "' text-anchor='middle'>" + CsvNumber(v) + "</text>";
    }
    s += "<text x='" + F1(kW - kRight) + "' y='" + F1(kH - 3) +
         "' text-anchor='end' class='unit'>simulated s</text>";
  }
  s += "<rect x='" + F1(kLeft) + "' y='" + F1(kTop) + "' width='" + F1(kW - kLeft - kRight) + "' height='" +
       F1(kH - kTop - kBottom) + "' class='frame'/>";
  return s;
}

// The points of one series as an SVG path (`step`: hold each value until the next point).
std::string PathOf(const Frame& f, const std::vector<SeriesPoint>& points, bool step) {
  std::string d;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double x = f.x(points[i].t_s), y = f.yv(points[i].value);
    if (i == 0) {
      d += "M" + F1(x) + " " + F1(y);
    } else if (step) {
      d += "H" + F1(x) + "V" + F1(y);
    } else {
      d += "L" + F1(x) + " " + F1(y);
    }
  }
  if (step && !points.empty()) d += "H" + F1(f.x(f.t.hi));
  return d;
}

double Median(std::vector<double>& v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

struct LineChart {
  const std::vector<Series>* series = nullptr;
  AxisKind kind;
  bool step = false;
  bool to_one = false;  // the axis reaches 1 (a score of 0..1)
  // Colour of a series by name (the page's drone colours, or the chart's own).
  std::map<std::string, std::string> colours;
};

// The lowest and highest value over all points (0, 0 with no points).
std::pair<double, double> ValueRange(const std::vector<Series>& series) {
  double lo = 0, hi = 0;
  bool any = false;
  for (const Series& s : series) {
    for (const SeriesPoint& p : s.points) {
      lo = any ? std::min(lo, p.value) : p.value;
      hi = any ? std::max(hi, p.value) : p.value;
      any = true;
    }
  }
  return {lo, hi};
}

// Too many series for a line each: the min..max band and the median line over time bins.
std::string EnvelopeSvg(const Frame& f, const std::vector<Series>& series, bool step) {
  const std::vector<EnvelopeBin> env = Envelope(series, f.t.hi, kEnvelopeBins, step);
  std::string band, median;
  for (const EnvelopeBin& b : env) {
    band += (band.empty() ? "M" : "L") + F1(f.x(b.t_s)) + " " + F1(f.yv(b.max));
  }
  for (auto it = env.rbegin(); it != env.rend(); ++it) {
    band += "L" + F1(f.x(it->t_s)) + " " + F1(f.yv(it->min));
  }
  for (const EnvelopeBin& b : env) {
    median += (median.empty() ? "M" : "L") + F1(f.x(b.t_s)) + " " + F1(f.yv(b.median));
  }
  return "<path d='" + band + "Z' class='band'><title>min..max of " + std::to_string(series.size()) +
         "</title></path><path d='" + median + "' class='median'><title>median of " +
         std::to_string(series.size()) + "</title></path>";
}

// One line per series in its colour (the first palette colour when it has none); a lone point
// shows as a dot.
std::string SeriesLinesSvg(const Frame& f, const LineChart& c) {
  std::string s;
  for (const Series& one : *c.series) {
    auto found = c.colours.find(one.name);
    const std::string colour = found == c.colours.end() ? std::string(kPalette[0]) : found->second;
    s += "<path d='" + PathOf(f, one.points, c.step) + "' stroke='" + colour + "' class='line'><title>" +
         HtmlEscape(one.name) + "</title></path>";
    if (one.points.size() == 1) {
      s += "<circle cx='" + F1(f.x(one.points[0].t_s)) + "' cy='" + F1(f.yv(one.points[0].value)) +
           "' r='2.5' fill='" + colour + "'/>";
    }
  }
  return s;
}

std::string LineSvg(const LineChart& c, double t_end_s) {
  auto [lo, hi] = ValueRange(*c.series);
  if (c.to_one) hi = std::max(hi, 1.0);
  Frame f{TimeAxis(t_end_s), ChooseAxis(lo, hi, c.kind, 5)};
  std::string s = Axes(f, true);
  s += c.series->size() > kMaxLines ? EnvelopeSvg(f, *c.series, c.step) : SeriesLinesSvg(f, c);
  return s + "</svg>";
}

// The colour of label i of n: the palette while it suffices, else n hues around the circle in
// two lightnesses (a SAR lifter goes through ~20 stages), so that no two labels share one.
std::string LabelColour(std::size_t i, std::size_t n) {
  if (n <= kPaletteSize) return kPalette[i];
  const double hue = 360.0 * static_cast<double>(i) / static_cast<double>(n);
  return "hsl(" + F1(hue) + ",62%," + (i % 2 == 0 ? "48%" : "68%") + ")";
}

// The distinct state labels of all lanes, sorted, each with its colour.
class LaneLabels {
 public:
  explicit LaneLabels(const std::vector<Lane>& lanes) {
    std::set<std::string> seen;
    for (const Lane& l : lanes) {
      for (const StateSpan& sp : l.spans) seen.insert(sp.label);
    }
    labels_.assign(seen.begin(), seen.end());
  }
  const std::vector<std::string>& labels() const { return labels_; }
  std::string Colour(const std::string& label) const {
    const auto i =
        static_cast<std::size_t>(std::find(labels_.begin(), labels_.end(), label) - labels_.begin());
    return LabelColour(i, labels_.size());
  }

 private:
  std::vector<std::string> labels_;
};

// The time grid, its tick labels and the unit under the lanes, which end at `bottom`.
std::string LaneTimeAxis(const Frame& f, double bottom) {
  std::string s;
  for (double v : f.t.Ticks()) {
    s += "<line x1='" + F1(f.x(v)) + "' x2='" + F1(f.x(v)) + "' y1='" + F1(kTop) + "' y2='" + F1(bottom) +
         "' class='grid'/><text x='" + F1(f.x(v)) + "' y='" + F1(bottom + 14) + "' text-anchor='middle'>" +
         CsvNumber(v) + "</text>";
  }
  return s + "<text x='" + F1(kW - kRight) + "' y='" + F1(bottom + 27) +
         "' text-anchor='end' class='unit'>simulated s</text>";
}

// One lane of height `row` at `y`: its name when the row is tall enough, a rectangle per span.
std::string LaneRowSvg(const Frame& f, const Lane& lane, double y, double row, const LaneLabels& labels) {
  std::string s;
  if (row >= 9) {
    s += "<text x='" + F1(kLeft - 5) + "' y='" + F1(y + row / 2 + 4) + "' text-anchor='end'>" +
         HtmlEscape(lane.name) + "</text>";
  }
  for (const StateSpan& sp : lane.spans) {
    const double x0 = f.x(sp.t0_s), x1 = f.x(std::max(sp.t1_s, sp.t0_s));
    // Rows of 4 px or more keep a 1 px gap; thinner ones (many nodes) are solid.
    s += "<rect x='" + F1(x0) + "' y='" + F1(y + (row >= 4 ? 0.5 : 0.0)) + "' width='" +
         F1(std::max(0.8, x1 - x0)) + "' height='" + F1(row >= 4 ? row - 1 : row) + "' fill='" +
         labels.Colour(sp.label) + "'><title>" + HtmlEscape(lane.name) + ": " + HtmlEscape(sp.label) + " " +
         F3(sp.t0_s) + "-" + F3(sp.t1_s) + " s</title></rect>";
  }
  return s;
}

std::string LaneSvg(const std::vector<Lane>& lanes, double t_end_s, std::string* legend) {
  const LaneLabels labels(lanes);
  const double rows_h = kH - kTop - kBottom;
  const double row =
      std::clamp(rows_h / static_cast<double>(std::max<std::size_t>(1, lanes.size())), 2.0, 18.0);
  const double height = kTop + kBottom + row * static_cast<double>(lanes.size());
  Frame f{TimeAxis(t_end_s), PlotAxis{}};
  std::string s = "<svg width='" + F1(kW) + "' height='" + F1(height) + "' class='ts'>";
  s += LaneTimeAxis(f, kTop + row * static_cast<double>(lanes.size()));
  for (std::size_t i = 0; i < lanes.size(); ++i) {
    s += LaneRowSvg(f, lanes[i], kTop + row * static_cast<double>(i), row, labels);
  }
  if (row < 9) {  // rows too thin for names: the count instead
    s += "<text x='" + F1(kLeft - 5) + "' y='" + F1(kTop + 10) + "' text-anchor='end'>" +
         std::to_string(lanes.size()) + "</text><text x='" + F1(kLeft - 5) + "' y='" + F1(kTop + 22) +
         "' text-anchor='end'>nodes</text>";
  }
  for (const std::string& label : labels.labels()) {
    *legend += "<span class='key'><i style='background:" + labels.Colour(label) + "'></i>" +
               HtmlEscape(label) + "</span>";
  }
  return s + "</svg>";
}

std::map<std::string, std::string> DroneColours(const TrialSeries& s) {
  std::set<std::string> names;
  for (const auto* list : {&s.altitude_m, &s.speed_m_s, &s.nearest_m, &s.radio_loss, &s.radio_rtt_ms,
                           &s.raft_term, &s.battery}) {
    for (const Series& one : *list) names.insert(one.name);
  }
  std::map<std::string, std::string> colours;
  std::size_t i = 0;
  for (const std::string& n : names) colours[n] = kPalette[i++ % kPaletteSize];
  return colours;
}

}  // namespace

std::vector<EnvelopeBin> Envelope(const std::vector<Series>& series, double t_end_s, int bins, bool step) {
  std::vector<EnvelopeBin> out;
  if (bins <= 0 || !(t_end_s > 0)) return out;
  const double width = t_end_s / bins;
  std::vector<std::vector<double>> values(static_cast<std::size_t>(bins));
  for (const Series& s : series) {
    if (step) {
      // Held values: each bin gets the series' value at the bin's end (once it has one).
      std::size_t next = 0;
      for (int i = 0; i < bins; ++i) {
        const double end = (i + 1) * width;
        while (next < s.points.size() && s.points[next].t_s <= end) ++next;
        if (next > 0) values[static_cast<std::size_t>(i)].push_back(s.points[next - 1].value);
      }
      continue;
    }
    for (const SeriesPoint& p : s.points) {
      const int i = std::clamp(static_cast<int>(std::floor(p.t_s / width)), 0, bins - 1);
      values[static_cast<std::size_t>(i)].push_back(p.value);
    }
  }
  for (int i = 0; i < bins; ++i) {
    std::vector<double>& v = values[static_cast<std::size_t>(i)];
    if (v.empty()) continue;
    EnvelopeBin b;
    b.t_s = (i + 0.5) * width;
    b.min = *std::min_element(v.begin(), v.end());
    b.max = *std::max_element(v.begin(), v.end());
    b.median = Median(v);
    out.push_back(b);
  }
  return out;
}

namespace {

// The y axes of the line panels.
struct PanelAxes {
  AxisKind from_zero;  // lengths, speeds, times
  AxisKind rate;       // 0..1 fractions
  AxisKind term;       // integers
  AxisKind score;      // order is a mean cosine: -1..1; safety and union 0..1
};

PanelAxes MakePanelAxes() {
  PanelAxes axes;
  axes.from_zero.from_zero = true;
  axes.rate = axes.from_zero;
  axes.rate.max = 1.0;
  axes.term.integer = true;
  axes.score.from_zero = true;
  axes.score.non_negative = false;
  axes.score.max = 1.0;
  return axes;
}

TrialPanel LinePanel(std::string caption, const LineChart& chart, double t_end_s, std::string missing) {
  TrialPanel p;
  p.caption = std::move(caption);
  if (chart.series->empty()) {
    p.missing = std::move(missing);
  } else {
    p.svg = LineSvg(chart, t_end_s);
    if (chart.series->size() > kMaxLines) {
      p.caption += " (" + std::to_string(chart.series->size()) + " series: min..max, median)";
    }
  }
  return p;
}

TrialPanel LanePanel(std::string caption, const std::vector<Lane>& rows, double t_end_s,
                     std::string missing) {
  TrialPanel p;
  p.caption = std::move(caption);
  if (rows.empty()) {
    p.missing = std::move(missing);
  } else {
    std::string legend;
    p.svg = LaneSvg(rows, t_end_s, &legend);
    p.svg += "<div class='legend'>" + legend + "</div>";
  }
  return p;
}

// The flocking panel's legend: one key per score in its colour.
std::string FlockLegend(const std::vector<Series>& flock, const std::map<std::string, std::string>& colours) {
  std::string legend;
  for (const Series& one : flock) {
    const auto colour = colours.find(one.name);
    legend += "<span class='key'><i style='background:" + (colour == colours.end() ? "" : colour->second) +
              "'></i>" + one.name + "</span>";
  }
  return "<div class='legend'>" + legend + "</div>";
}

// "flocking": order, safety and union in fixed colours, 0..1 (order down to -1), with a legend.
TrialPanel FlockPanel(const TrialSeries& s, const AxisKind& score,
                      const std::map<std::string, std::string>& colours) {
  TrialPanel p = LinePanel("flocking: order, safety, union (the leader's member table)",
                           {&s.flock, score, false, /*to_one=*/true, colours}, s.t_end_s,
                           "no event=flock_metrics in the logs");
  if (!s.flock.empty()) p.svg += FlockLegend(s.flock, colours);
  return p;
}

}  // namespace

std::vector<TrialPanel> TrialPanels(const TrialSeries& s) {
  const std::map<std::string, std::string> drones = DroneColours(s);
  const PanelAxes axes = MakePanelAxes();
  const std::map<std::string, std::string> flock_colours = {
      {"order", kPalette[0]}, {"safety", kPalette[2]}, {"union", kPalette[4]}};
  const double t = s.t_end_s;
  const std::string no_truth = "no truth.csv";
  const std::string no_leader = "no event=leader_elected in the logs";
  return {
      LinePanel("altitude [m]", {&s.altitude_m, axes.from_zero, false, false, drones}, t, no_truth),
      LinePanel("speed [m/s]", {&s.speed_m_s, axes.from_zero, false, false, drones}, t, no_truth),
      LinePanel("nearest neighbour [m]", {&s.nearest_m, axes.from_zero, false, false, drones}, t,
                "no truth.csv with two drones or more"),
      LinePanel("radio loss per node", {&s.radio_loss, axes.rate, false, false, drones}, t,
                "no event=link in the logs"),
      LinePanel("radio RTT [ms]", {&s.radio_rtt_ms, axes.from_zero, false, false, drones}, t,
                "no event=link with an answered ping in the logs"),
      LinePanel("Raft term", {&s.raft_term, axes.term, /*step=*/true, false, drones}, t, no_leader),
      LanePanel("Raft leader each node followed", s.raft_leader, t, no_leader),
      LinePanel("battery [fraction]", {&s.battery, axes.rate, false, false, drones}, t,
                "no event=battery in the logs"),
      LanePanel("mission stage", s.mission_stage, t, "no event=mission_stage in the logs"),
      FlockPanel(s, axes.score, flock_colours),
  };
}

std::string TrialPlotsHtml(const TrialPlotsPage& page, const TrialSeries& s) {
  std::string h =
      "<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>" + HtmlEscape(page.title) +
      "</title>\n<style>body{font-family:sans-serif;margin:1.5em;color:#222}h1{font-size:20px}"
      ".plots{display:flex;flex-wrap:wrap;gap:1em 1.5em}.plots figure{margin:0;width:460px}"
      "figcaption{font-size:13px;color:#444;margin-bottom:2px}svg.ts text{font-size:10px;fill:#555}"
      "svg.ts .unit{fill:#888}.grid{stroke:#eee}.frame{fill:none;stroke:#bbb}"
      ".line{fill:none;stroke-width:1.4}.band{fill:#cfe2ff;stroke:none}.median{fill:none;stroke:#1f4e9c;"
      "stroke-width:1.6}.none{width:460px;color:#888;font-size:13px;border:1px dashed #ccc;padding:2em 0;"
      "text-align:center}.legend,.keys{font-size:12px;max-width:460px}.key{margin-right:.9em;white-space:"
      "nowrap}"
      ".key i{display:inline-block;width:10px;height:10px;margin-right:3px;vertical-align:-1px}"
      "img.traj{max-width:460px;border:1px solid #ddd}</style></head><body>\n<h1>" +
      HtmlEscape(page.title) + "</h1>\n";
  if (!page.summary.empty()) h += "<p>" + HtmlEscape(page.summary) + "</p>\n";
  const std::map<std::string, std::string> drones = DroneColours(s);
  if (!drones.empty() && drones.size() <= kMaxLines) {
    h += "<p class='keys'>";
    for (const auto& [name, colour] : drones) {
      h += "<span class='key'><i style='background:" + colour + "'></i>" + HtmlEscape(name) + "</span>";
    }
    h += "</p>\n";
  } else if (drones.size() > kMaxLines) {
    h += "<p class='keys'>" + std::to_string(drones.size()) +
         " drones: each line panel shows the swarm's min..max (band) and median over time.</p>\n";
  }
  h += "<div class='plots'>\n";
  for (const TrialPanel& p : TrialPanels(s)) {
    h += "<figure><figcaption>" + HtmlEscape(p.caption) + "</figcaption>";
    h += p.svg.empty() ? "<div class='none'>" + HtmlEscape(p.missing) + "</div>" : p.svg;
    h += "</figure>\n";
  }
  if (page.has_trajectories) {
    h += "<figure><figcaption>trajectories (from above)</figcaption><a href='trajectories.png'>"
         "<img class='traj' src='trajectories.png' alt='trajectories'></a></figure>\n";
  }
  h += "</div>\n</body></html>\n";
  return h;
}

}  // namespace swarmbox::report
