#include "guest_measurements.hpp"

#include <algorithm>
#include <cstdio>
#include <regex>
#include <set>

namespace swarmbox::netem_guest {
namespace {

std::string Fixed(double value, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

}  // namespace

Fields SampleFields(const faults::testing::ProbeSample& s) {
  const double loss = s.sent == 0 ? 0.0 : 1.0 - static_cast<double>(s.received()) / s.sent;
  Fields f = {{"sent", std::to_string(s.sent)},
              {"received", std::to_string(s.received())},
              {"datagrams", std::to_string(s.datagrams)},
              {"loss", Fixed(loss, 5)},
              {"send_late_max_ms", Fixed(static_cast<double>(s.max_send_late_us) / 1000.0, 3)}};
  if (s.received() > 1) {
    f.insert(f.end(), {{"mean_ms", Fixed(s.Mean(), 3)},
                       {"sd_ms", Fixed(s.StdDev(), 3)},
                       {"min_ms", Fixed(s.Quantile(0.0), 3)},
                       {"p50_ms", Fixed(s.Quantile(0.5), 3)},
                       {"p99_ms", Fixed(s.Quantile(0.99), 3)},
                       {"max_ms", Fixed(s.Quantile(1.0), 3)}});
  }
  return f;
}

LossBursts CountLossBursts(const faults::testing::ProbeSample& s) {
  LossBursts b;
  std::uint32_t expected = 0;
  for (std::uint32_t seq : s.seqs) {
    if (seq != expected) ++b.bursts;
    expected = seq + 1;
  }
  if (expected != s.sent) ++b.bursts;
  const std::uint32_t lost = s.sent > s.received() ? s.sent - s.received() : 0;
  b.mean_length = b.bursts > 0 ? static_cast<double>(lost) / b.bursts : 0.0;
  return b;
}

double EarlyFraction(const faults::testing::ProbeSample& s, double threshold_ms) {
  if (s.delay_ms.empty()) return 0.0;
  const auto early =
      std::count_if(s.delay_ms.begin(), s.delay_ms.end(), [&](double d) { return d < threshold_ms; });
  return static_cast<double>(early) / static_cast<double>(s.delay_ms.size());
}

double OutOfOrderFraction(const faults::testing::ProbeSample& s) {
  std::set<std::uint32_t> seen;
  std::size_t firsts = 0, overtaken = 0;
  bool any = false;
  std::uint32_t highest = 0;
  for (const auto& a : s.arrivals) {
    if (!seen.insert(a.seq).second) continue;  // a duplicate's second copy
    ++firsts;
    if (any && a.seq < highest) ++overtaken;
    if (!any || a.seq > highest) highest = a.seq;
    any = true;
  }
  return firsts == 0 ? 0.0 : static_cast<double>(overtaken) / static_cast<double>(firsts);
}

std::optional<double> ArrivalRateKbit(const faults::testing::ProbeSample& s, std::size_t wire_bytes) {
  if (s.arrivals.size() < 2) return std::nullopt;
  std::vector<double> t;
  t.reserve(s.arrivals.size());
  for (const auto& a : s.arrivals) t.push_back(static_cast<double>(a.arrived_us));
  std::sort(t.begin(), t.end());
  // Least squares of arrival time on arrival index: the slope is the time per datagram.
  const double n = static_cast<double>(t.size());
  const double x_mean = (n - 1.0) / 2.0;
  double y_mean = 0.0;
  for (double y : t) y_mean += y;
  y_mean /= n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double dx = static_cast<double>(i) - x_mean;
    sxy += dx * (t[i] - y_mean);
    sxx += dx * dx;
  }
  const double us_per_datagram = sxy / sxx;
  if (us_per_datagram <= 0.0) return std::nullopt;
  return static_cast<double>(wire_bytes) * 8.0 / us_per_datagram * 1000.0;  // bit/us = Mbit/s
}

std::string NormalizeTcListing(std::string_view listing) {
  static const std::regex kAutoHandle(R"((qdisc \S+ )[89a-f][0-9a-f]{3}:)");
  static const std::regex kDirect(R"( direct_packets_stat \d+)");
  std::string out = std::regex_replace(std::string(listing), kAutoHandle, "$1auto:");
  return std::regex_replace(out, kDirect, "");
}

}  // namespace swarmbox::netem_guest
