#include "swarmbox/report/plot_axis.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::report {

AxisKind AxisKindOf(std::string_view metric) {
  AxisKind k;
  if (metric == "detections" || metric == "victims_confirmed" || metric == "victims_rescued" ||
      metric == "collisions" || metric == "leader_changes" || metric == "false_alarms_rejected" ||
      metric == "false_victims_confirmed" || metric == "false_victims_rescued" || metric == "victims_missed") {
    k.from_zero = true;
    k.integer = true;
  } else if (metric == "radio_loss") {
    k.from_zero = true;
    k.max = 1.0;
  }
  return k;
}

double NiceStep(double raw) {
  if (!(raw > 0) || !std::isfinite(raw)) return 1.0;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    // A little tolerance: 0.2 / 1 must give 0.2, not 0.5, after floating-point division.
    if (m * p >= raw * (1 - 1e-9)) return m * p;
  }
  return 10.0 * p;
}

std::vector<double> PlotAxis::Ticks() const {
  std::vector<double> out;
  if (!(step > 0)) return out;
  // step = mantissa x 10^exponent; a tick k * step is (k * mantissa) scaled once, so 3 x 0.05 is
  // the double nearest 0.15, not 0.15000000000000002.
  const int exponent = static_cast<int>(std::floor(std::log10(step) + 1e-9));
  const double scale = std::pow(10.0, std::abs(exponent));
  const double mantissa = std::round(exponent >= 0 ? step / scale : step * scale);
  auto tick = [&](long long k) {
    const double units = static_cast<double>(k) * mantissa;
    return exponent >= 0 ? units * scale : units / scale;
  };
  const long long first = std::llround(lo / step);
  const long long n = std::llround((hi - lo) / step);
  for (long long i = 0; i <= n; ++i) {
    const double v = tick(first + i);
    out.push_back(v == 0.0 ? 0.0 : v);  // no "-0"
  }
  return out;
}

PlotAxis ChooseAxis(double data_min, double data_max, const AxisKind& kind, int max_ticks) {
  max_ticks = std::max(2, max_ticks);
  if (!std::isfinite(data_min) || !std::isfinite(data_max)) data_min = data_max = 0;
  if (data_min > data_max) std::swap(data_min, data_max);
  double lower = data_min;
  double upper = data_max;
  if (kind.from_zero && lower >= 0) lower = 0;
  if (upper - lower <= 0) {
    // One value: a band around it, as wide as a tenth of it (or 1 at 0), not below the floor.
    const double half = kind.integer ? 0.5 : (upper != 0 ? std::abs(upper) * 0.05 : 0.5);
    lower -= half;
    upper += half;
    if (kind.from_zero || (kind.non_negative && data_min >= 0 && lower < 0)) lower = std::max(lower, 0.0);
    if (kind.integer) upper = std::max(upper, lower + 1);
  }
  PlotAxis a;
  double step = NiceStep((upper - lower) / (max_ticks - 1));
  if (kind.integer) step = std::max(step, 1.0);
  for (int guard = 0; guard < 64; ++guard) {
    a.step = step;
    a.lo = std::floor(lower / step + 1e-9) * step;
    a.hi = std::ceil(upper / step - 1e-9) * step;
    if (kind.non_negative && data_min >= 0) a.lo = std::max(a.lo, 0.0);
    if (kind.max && data_max <= *kind.max) a.hi = std::min(a.hi, *kind.max);
    if (std::llround((a.hi - a.lo) / step) + 1 <= max_ticks) break;
    step = NiceStep(step * 1.000001);  // the next step of the series
  }
  if (a.hi <= a.lo) a.hi = a.lo + a.step;
  return a;
}

}  // namespace swarmbox::report
