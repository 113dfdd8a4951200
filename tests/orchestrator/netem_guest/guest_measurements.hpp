// What the netem guest reports from a probe run and from tc's listings. Pure.
//
//   auto fields = SampleFields(sample);          // sent= received= loss= mean_ms= sd_ms= p50_ms= ...
//   LossBursts b = CountLossBursts(sample);      // runs of consecutive lost numbers
//   double early = EarlyFraction(sample, 5.0);   // arrived sooner than 5 ms (netem's reorder)
//   auto kbit = ArrivalRateKbit(sample, 1042);   // what a rate limit let through [kbit/s]
//   NormalizeTcListing(qdiscs) == NormalizeTcListing(qdiscs_later)   // same tree, kernel handles aside
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "udp_probe.hpp"

namespace swarmbox::netem_guest {

using Fields = std::vector<std::pair<std::string, std::string>>;

// sent, received, datagrams, loss (1 - received / sent), send_late_max_ms (the sender's worst
// lateness: how long the guest went unscheduled), mean_ms, sd_ms, min_ms, p50_ms, p99_ms, max_ms
// (times with 3 decimals; loss with 5).
Fields SampleFields(const faults::testing::ProbeSample& sample);

struct LossBursts {
  int bursts = 0;            // runs of consecutive numbers never received
  double mean_length = 0.0;  // lost / bursts (0 without loss)
};
LossBursts CountLossBursts(const faults::testing::ProbeSample& sample);

// The fraction of the received numbers whose delay is under `threshold_ms`.
double EarlyFraction(const faults::testing::ProbeSample& sample, double threshold_ms);

// The fraction of arrivals (first copies only) that came after a higher number had arrived: the
// packets something overtook.
double OutOfOrderFraction(const faults::testing::ProbeSample& sample);

// The rate at which datagrams of `wire_bytes` each (on the link: payload + UDP + IP + Ethernet
// headers) arrived [kbit/s, 1000 bit/s]: the least-squares slope of arrival time on arrival index,
// so a late wake-up at the first or last arrival moves it little. Meaningful while the datagrams
// queue behind the limit (offered faster than the rate). nullopt with fewer than two arrivals or
// no time between them.
std::optional<double> ArrivalRateKbit(const faults::testing::ProbeSample& sample, std::size_t wire_bytes);

// A `tc qdisc|class|filter show` listing with what the kernel picks by itself masked, so two trees
// built by the same commands compare equal: handles of qdiscs added without one (the kernel's
// 8001:, 8002: ..., shown as "auto:") and the htb root's packet counter direct_packets_stat.
std::string NormalizeTcListing(std::string_view listing);

}  // namespace swarmbox::netem_guest
