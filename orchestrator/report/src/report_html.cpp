#include "swarmbox/report/report_html.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "swarmbox/report/plot_axis.hpp"
#include "swarmbox/report/results_csv.hpp"

namespace swarmbox::report {

namespace {

const std::vector<std::string>& Outcomes() {
  static const std::vector<std::string> k = {"success", "failure", "timeout", "error"};
  return k;
}

std::string Fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

double Quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0;
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const auto hi = std::min(lo + 1, sorted.size() - 1);
  const double frac = pos - static_cast<double>(lo);
  return sorted[lo] + (sorted[hi] - sorted[lo]) * frac;
}

// Levels of factor i in the order first seen in code order.
std::vector<std::pair<char, std::string>> LevelsOf(const std::vector<TrialRecord>& records,
                                                   std::size_t i) {
  std::map<char, std::string> by_code;
  for (const TrialRecord& r : records) {
    if (i < r.meta.code.size() && i < r.meta.levels.size()) by_code[r.meta.code[i]] = r.meta.levels[i];
  }
  return {by_code.begin(), by_code.end()};
}

// A box plot's geometry [px]: one column kBoxColumnW wide per box after the kBoxLeft margin.
constexpr double kBoxColumnW = 110, kBoxPlotH = 220, kBoxTop = 14, kBoxBottom = 40, kBoxLeft = 56;
constexpr double kBoxW = 36;  // the IQR box's width

// Where values go on a box plot: the axis, and the y of a value.
struct BoxFrame {
  PlotAxis axis;
  double y(double v) const {
    return kBoxTop + (axis.hi - v) / (axis.hi - axis.lo) * (kBoxPlotH - kBoxTop - kBoxBottom);
  }
};

// The axis over all boxes that have values.
PlotAxis BoxAxis(const std::vector<std::pair<std::string, BoxStats>>& boxes, const AxisKind& kind) {
  double data_lo = 0, data_hi = 0;
  bool any = false;
  for (const auto& [label, b] : boxes) {
    if (b.n == 0) continue;
    data_lo = any ? std::min(data_lo, b.min) : b.min;
    data_hi = any ? std::max(data_hi, b.max) : b.max;
    any = true;
  }
  return ChooseAxis(data_lo, data_hi, kind);
}

// One box centred at cx: whisker line and caps, the IQR box with its numbers, median, outliers.
std::string BoxSvg(const std::string& label, const BoxStats& b, double cx, const BoxFrame& f) {
  std::string s = "<line x1='" + Fmt(cx) + "' x2='" + Fmt(cx) + "' y1='" + Fmt(f.y(b.whisker_low)) +
                  "' y2='" + Fmt(f.y(b.whisker_high)) + "' class='whisker'/>";
  for (double w : {b.whisker_low, b.whisker_high}) {
    s += "<line x1='" + Fmt(cx - kBoxW / 4) + "' x2='" + Fmt(cx + kBoxW / 4) + "' y1='" + Fmt(f.y(w)) +
         "' y2='" + Fmt(f.y(w)) + "' class='whisker'/>";
  }
  s += "<rect x='" + Fmt(cx - kBoxW / 2) + "' y='" + Fmt(f.y(b.q3)) + "' width='" + Fmt(kBoxW) +
       "' height='" + Fmt(std::max(1.0, f.y(b.q1) - f.y(b.q3))) + "' class='iqr'><title>" +
       HtmlEscape(label) + ": n=" + std::to_string(b.n) + " min " + Fmt(b.min) + " q1 " + Fmt(b.q1) +
       " median " + Fmt(b.median) + " q3 " + Fmt(b.q3) + " max " + Fmt(b.max) + "</title></rect>";
  s += "<line x1='" + Fmt(cx - kBoxW / 2) + "' x2='" + Fmt(cx + kBoxW / 2) + "' y1='" + Fmt(f.y(b.median)) +
       "' y2='" + Fmt(f.y(b.median)) + "' class='median'/>";
  for (double o : b.outliers) {
    s += "<circle cx='" + Fmt(cx) + "' cy='" + Fmt(f.y(o)) + "' r='3' class='outlier'/>";
  }
  return s;
}

std::string BoxPlotSvg(const std::vector<std::pair<std::string, BoxStats>>& boxes, const AxisKind& kind) {
  const BoxFrame f{BoxAxis(boxes, kind)};
  const double width = kBoxLeft + kBoxColumnW * static_cast<double>(boxes.size()) + 10;
  std::string s = "<svg width='" + Fmt(width) + "' height='" + Fmt(kBoxPlotH) + "' class='box'>";
  for (double v : f.axis.Ticks()) {
    s += "<line x1='" + Fmt(kBoxLeft - 4) + "' x2='" + Fmt(width - 10) + "' y1='" + Fmt(f.y(v)) + "' y2='" +
         Fmt(f.y(v)) + "' class='grid'/><text x='" + Fmt(kBoxLeft - 6) + "' y='" + Fmt(f.y(v) + 4) +
         "' text-anchor='end'>" + CsvNumber(v) + "</text>";
  }
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const auto& [label, b] = boxes[i];
    const double cx = kBoxLeft + kBoxColumnW * (static_cast<double>(i) + 0.5);
    s += "<text x='" + Fmt(cx) + "' y='" + Fmt(kBoxPlotH - kBoxBottom + 16) + "' text-anchor='middle'>" +
         HtmlEscape(label) + "</text><text x='" + Fmt(cx) + "' y='" + Fmt(kBoxPlotH - kBoxBottom + 32) +
         "' text-anchor='middle' class='n'>n=" + std::to_string(b.n) + "</text>";
    if (b.n != 0) s += BoxSvg(label, b, cx, f);
  }
  return s + "</svg>";
}

constexpr char kPlotCss[] =
    "svg.box text{font-family:sans-serif;font-size:11px;fill:#333}svg.box .n{fill:#777}"
    ".grid{stroke:#eee}.whisker{stroke:#555}.iqr{fill:#cfe2ff;stroke:#1f4e9c}"
    ".median{stroke:#1f4e9c;stroke-width:2}.outlier{fill:none;stroke:#b42318}";

}  // namespace

BoxStats ComputeBoxStats(std::vector<double> values) {
  BoxStats b;
  values.erase(std::remove_if(values.begin(), values.end(),
                              [](double v) { return !std::isfinite(v); }),
               values.end());
  b.n = values.size();
  if (values.empty()) return b;
  std::sort(values.begin(), values.end());
  b.min = values.front();
  b.max = values.back();
  b.q1 = Quantile(values, 0.25);
  b.median = Quantile(values, 0.5);
  b.q3 = Quantile(values, 0.75);
  const double iqr = b.q3 - b.q1;
  const double low_fence = b.q1 - 1.5 * iqr;
  const double high_fence = b.q3 + 1.5 * iqr;
  b.whisker_low = b.q1;
  b.whisker_high = b.q3;
  for (double v : values) {
    if (v < low_fence || v > high_fence) {
      b.outliers.push_back(v);
    } else {
      b.whisker_low = std::min(b.whisker_low, v);
      b.whisker_high = std::max(b.whisker_high, v);
    }
  }
  return b;
}

std::string HtmlEscape(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::vector<ReportPlot> ReportPlots(const std::vector<std::string>& factors,
                                    const std::vector<TrialRecord>& records) {
  std::vector<ReportPlot> plots;
  std::vector<std::string> metrics = {"wall_s", "sim_s"};
  metrics.insert(metrics.end(), MetricNames().begin(), MetricNames().end());
  for (const std::string& m : metrics) {
    auto value = [&](const TrialRecord& r) -> std::optional<double> {
      if (m == "wall_s") return r.wall_s;
      if (m == "sim_s") return r.sim_s;
      auto it = r.metrics.find(m);
      return it == r.metrics.end() ? std::nullopt : it->second;
    };
    if (std::none_of(records.begin(), records.end(),
                     [&](const TrialRecord& r) { return value(r).has_value(); })) {
      continue;
    }
    for (std::size_t i = 0; i < factors.size(); ++i) {
      std::vector<std::pair<std::string, BoxStats>> boxes;
      for (const auto& [code, label] : LevelsOf(records, i)) {
        std::vector<double> values;
        for (const TrialRecord& r : records) {
          if (i < r.meta.code.size() && r.meta.code[i] == code) {
            if (auto v = value(r)) values.push_back(*v);
          }
        }
        boxes.emplace_back(label, ComputeBoxStats(std::move(values)));
      }
      plots.push_back({m, factors[i], BoxPlotSvg(boxes, AxisKindOf(m))});
    }
  }
  return plots;
}

std::string PlotFileName(const ReportPlot& plot) {
  std::string name = plot.metric + "_by_" + plot.factor;
  for (char& c : name) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '_' || c == '-';
    if (!keep) c = '_';
  }
  return name + ".svg";
}

std::string StandalonePlotSvg(const ReportPlot& plot) {
  // The inline <svg> of the page (HTML needs no namespace; a file does), with its style and a
  // title, as a file of its own.
  const std::string& svg = plot.svg;
  const std::size_t open_end = svg.find('>');
  return "<?xml version='1.0' encoding='utf-8'?>\n<svg xmlns='http://www.w3.org/2000/svg'" +
         svg.substr(4, open_end + 1 - 4) + "<style>" + kPlotCss + "</style><title>" +
         HtmlEscape(plot.metric) + " by " + HtmlEscape(plot.factor) + "</title>" +
         svg.substr(open_end + 1) + "\n";
}

namespace {

std::string HtmlHead(std::string_view title) {
  return "<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>" + HtmlEscape(title) +
         "</title>\n<style>body{font-family:sans-serif;margin:2em;color:#222}"
         "table{border-collapse:collapse;margin:.5em 0 1.5em}td,th{border:1px solid #ccc;"
         "padding:3px 8px;text-align:left;font-size:13px}th{background:#f3f3f3}"
         ".success{color:#1a7f37}.failure{color:#b42318}.timeout{color:#b54708}.error{color:#6941c6}"
         "svg.box text{font-size:11px;fill:#333}svg.box .n{fill:#777}.grid{stroke:#eee}"
         ".whisker{stroke:#555}.iqr{fill:#cfe2ff;stroke:#1f4e9c}.median{stroke:#1f4e9c;"
         "stroke-width:2}.outlier{fill:none;stroke:#b42318}.plots{display:flex;flex-wrap:wrap;"
         "gap:1.5em}.plots figure{margin:0}figcaption{font-size:13px;color:#555}"
         "img.thumb{width:90px;height:90px;object-fit:contain;border:1px solid #ddd}</style>"
         "</head><body>\n<h1>" + HtmlEscape(title) + "</h1>\n";
}

// The outcome totals, then a table of outcomes per level of each factor.
std::string OutcomesSection(const std::vector<std::string>& factors, const std::vector<TrialRecord>& records) {
  std::string h;
  std::map<std::string, int> totals;
  for (const TrialRecord& r : records) totals[r.outcome] += 1;
  h += "<p>" + std::to_string(records.size()) + " trials:";
  for (const std::string& o : Outcomes()) {
    h += " <span class='" + o + "'>" + o + " " + std::to_string(totals[o]) + "</span>";
  }
  h += "</p>\n<h2>Outcomes per factor level</h2>\n";
  for (std::size_t i = 0; i < factors.size(); ++i) {
    h += "<table><tr><th>" + HtmlEscape(factors[i]) + "</th>";
    for (const std::string& o : Outcomes()) h += "<th class='" + o + "'>" + o + "</th>";
    h += "</tr>";
    for (const auto& [code, label] : LevelsOf(records, i)) {
      std::map<std::string, int> counts;
      for (const TrialRecord& r : records) {
        if (i < r.meta.code.size() && r.meta.code[i] == code) counts[r.outcome] += 1;
      }
      h += "<tr><td>" + std::string(1, code) + ": " + HtmlEscape(label) + "</td>";
      for (const std::string& o : Outcomes()) h += "<td>" + std::to_string(counts[o]) + "</td>";
      h += "</tr>";
    }
    h += "</table>\n";
  }
  return h;
}

// The box plots of each metric by each factor.
std::string MetricsSection(const std::vector<std::string>& factors, const std::vector<TrialRecord>& records) {
  std::string h = "<h2>Metrics per factor level</h2>\n";
  const std::vector<ReportPlot> plots = ReportPlots(factors, records);
  for (std::size_t k = 0; k < plots.size(); ++k) {
    if (k == 0 || plots[k].metric != plots[k - 1].metric) {
      if (k != 0) h += "</div>\n";
      h += "<h3>" + HtmlEscape(plots[k].metric) + "</h3><div class='plots'>";
    }
    h += "<figure>" + plots[k].svg + "<figcaption>" + HtmlEscape(plots[k].metric) + " by " +
         HtmlEscape(plots[k].factor) + "</figcaption></figure>";
  }
  if (!plots.empty()) h += "</div>\n";
  const bool any_metric = std::any_of(records.begin(), records.end(), [](const TrialRecord& r) {
    return r.wall_s || r.sim_s ||
           std::any_of(r.metrics.begin(), r.metrics.end(), [](const auto& kv) { return kv.second.has_value(); });
  });
  if (!any_metric) h += "<p>No trial reported a metric.</p>\n";
  return h;
}

// One row of the trials table: links, levels, result, plots and the trajectories' thumbnail.
std::string TrialRow(const std::vector<std::string>& factors, const TrialRecord& r) {
  const std::string folder = HtmlEscape(r.folder);
  std::string h = "<tr><td><a href='" + folder + "/'>" + HtmlEscape(r.meta.id) + "</a> (<a href='" +
                  folder + "/logs/'>logs</a>, <a href='" + folder + "/result.json'>result</a>)</td><td>" +
                  HtmlEscape(r.meta.code) + "</td>";
  for (std::size_t i = 0; i < factors.size(); ++i) {
    h += "<td>" + (i < r.meta.levels.size() ? HtmlEscape(r.meta.levels[i]) : "") + "</td>";
  }
  h += "<td>" + std::to_string(r.meta.repetition) + "</td><td>" + std::to_string(r.meta.seed) +
       "</td><td>" + HtmlEscape(r.host) + "</td><td class='" + HtmlEscape(r.outcome) + "'>" +
       HtmlEscape(r.outcome) + "</td><td>" + HtmlEscape(r.reason) + "</td><td>" +
       (r.wall_s ? CsvNumber(*r.wall_s) : "") + "</td><td>" +
       (r.sim_s ? CsvNumber(*r.sim_s) : "") + "</td><td>";
  h += r.has_plots ? "<a href='" + folder + "/plots.html'>plots</a>" : std::string("none");
  h += "</td><td>";
  if (r.has_trajectories) {
    h += "<a href='" + folder + "/trajectories.png'><img class='thumb' loading='lazy' src='" +
         folder + "/trajectories.png' alt='trajectories of " + HtmlEscape(r.meta.id) + "'></a>";
  } else {
    h += "none";
  }
  h += "</td></tr>\n";
  return h;
}

std::string TrialsSection(const std::vector<std::string>& factors, const std::vector<TrialRecord>& records) {
  std::string h = "<h2>Trials</h2>\n<table><tr><th>trial</th><th>code</th>";
  for (const std::string& f : factors) h += "<th>" + HtmlEscape(f) + "</th>";
  h += "<th>rep</th><th>seed</th><th>host</th><th>outcome</th><th>reason</th><th>wall s</th>"
       "<th>sim s</th><th>over time</th><th>trajectories</th></tr>\n";
  for (const TrialRecord& r : records) h += TrialRow(factors, r);
  h += "</table>\n";
  return h;
}

}  // namespace

std::string ReportHtml(std::string_view title, const std::vector<std::string>& factors,
                       const std::vector<TrialRecord>& records) {
  return HtmlHead(title) + OutcomesSection(factors, records) + MetricsSection(factors, records) +
         TrialsSection(factors, records) + "</body></html>\n";
}

}  // namespace swarmbox::report
