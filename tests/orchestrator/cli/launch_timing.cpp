#include "launch_timing.hpp"

#include <algorithm>
#include <charconv>

namespace swarmbox::cli::testing {

namespace {

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
std::int64_t DaysFromCivil(std::int64_t y, std::int64_t m, std::int64_t d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const std::int64_t yoe = y - era * 400;
  const std::int64_t doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const std::int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

std::optional<std::int64_t> Digits(std::string_view s, std::size_t pos, std::size_t n) {
  if (pos + n > s.size()) return std::nullopt;
  std::int64_t v = 0;
  for (std::size_t i = pos; i < pos + n; ++i) {
    if (s[i] < '0' || s[i] > '9') return std::nullopt;
    v = v * 10 + (s[i] - '0');
  }
  return v;
}

double Seconds(std::int64_t ns) { return static_cast<double>(ns) / 1e9; }

}  // namespace

std::optional<std::int64_t> ParseDockerTimestampNs(std::string_view s) {
  // YYYY-MM-DDTHH:MM:SS[.fffffffff]Z
  if (s.size() < 20 || s[4] != '-' || s[7] != '-' || s[10] != 'T' || s[13] != ':' || s[16] != ':') {
    return std::nullopt;
  }
  auto y = Digits(s, 0, 4), mo = Digits(s, 5, 2), d = Digits(s, 8, 2);
  auto h = Digits(s, 11, 2), mi = Digits(s, 14, 2), sec = Digits(s, 17, 2);
  if (!y || !mo || !d || !h || !mi || !sec) return std::nullopt;
  if (*mo < 1 || *mo > 12 || *d < 1 || *d > 31 || *h > 23 || *mi > 59 || *sec > 60) return std::nullopt;
  std::size_t pos = 19;
  std::int64_t frac_ns = 0;
  if (pos < s.size() && s[pos] == '.') {
    ++pos;
    std::int64_t scale = 100'000'000;
    const std::size_t start = pos;
    while (pos < s.size() && s[pos] >= '0' && s[pos] <= '9') {
      if (pos - start >= 9) return std::nullopt;
      frac_ns += (s[pos] - '0') * scale;
      scale /= 10;
      ++pos;
    }
    if (pos == start) return std::nullopt;
  }
  if (pos + 1 != s.size() || s[pos] != 'Z') return std::nullopt;
  const std::int64_t days = DaysFromCivil(*y, *mo, *d);
  return ((days * 24 + *h) * 60 + *mi) * 60'000'000'000LL + *sec * 1'000'000'000LL + frac_ns;
}

std::optional<StampedLine> SplitStampedLine(std::string_view line) {
  const std::size_t space = line.find(' ');
  auto t = ParseDockerTimestampNs(line.substr(0, space));
  if (!t) return std::nullopt;
  return StampedLine{*t, space == std::string_view::npos ? std::string_view() : line.substr(space + 1)};
}

LaunchFigures ComputeLaunchFigures(const LaunchTimes& times, const std::vector<std::string>& agents) {
  LaunchFigures f;
  std::int64_t last_ready = times.spawn_ns;
  for (const std::string& a : agents) {
    auto it = times.ready_ns.find(a);
    if (it == times.ready_ns.end()) {
      f.not_ready.push_back(a);
    } else {
      last_ready = std::max(last_ready, it->second);
    }
  }
  if (f.not_ready.empty() && !agents.empty()) f.ready_s = Seconds(last_ready - times.spawn_ns);
  if (times.end_line_ns) {
    if (!times.died_ns.empty()) {
      const std::int64_t last = *std::max_element(times.died_ns.begin(), times.died_ns.end());
      f.end_to_stopped_s = Seconds(last - *times.end_line_ns);
    }
    if (times.exited_ns) f.end_to_exit_s = Seconds(*times.exited_ns - *times.end_line_ns);
  }
  return f;
}

std::optional<double> StartToReady(const LaunchTimes& times, const std::string& component) {
  auto start = times.start_ns.find(component);
  auto ready = times.ready_ns.find(component);
  if (start == times.start_ns.end() || ready == times.ready_ns.end()) return std::nullopt;
  return Seconds(ready->second - start->second);
}

}  // namespace swarmbox::cli::testing
