// The `event=link` log line (ARCHITECTURE.md "Log events"): one line per peer per report window,
// written by every agent that pings its peers (LinkProbe), read back by tests and benchmarks.
//
//   t=12.340 node=scout_1 event=link peer=scout_2 sent=10 received=9 loss=0.1000 late=0 dup=0
//       rtt_ms_mean=201.7 rtt_ms_sd=27.9 rtt_ms_p50=199.8 rtt_ms_p99=251.2 rtt_ms_max=251.2
//
// sent/received/loss follow LinkMonitor's settling rule (link_monitor.hpp): pings settled in the
// window, the answered ones, 1 - received/sent. The rtt_ms_* fields are present only when
// received > 0 (there is no RTT of nothing); t is the agent's simulated time, the RTTs are on the radio's
// clock [ms] (simulated with radio.model channel, wall with netem).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/radio/link_monitor.hpp"

namespace swarmbox::radio {

inline constexpr std::string_view kLinkEvent = "link";

LogEvent FormatLinkEvent(double sim_t_s, std::string_view self, const LinkWindow& window);

// A parsed `event=link` line.
struct LinkLine {
  double t_s = 0.0;
  std::string node;
  std::string peer;
  std::uint64_t sent = 0;
  std::uint64_t received = 0;
  double loss = 0.0;
  std::uint64_t late = 0;
  std::uint64_t duplicates = 0;
  bool has_rtt = false;     // the rtt_ms_* fields below were present
  double rtt_ms_mean = 0.0;
  double rtt_ms_sd = 0.0;
  double rtt_ms_p50 = 0.0;
  double rtt_ms_p99 = 0.0;
  double rtt_ms_max = 0.0;
};

// nullopt unless `line` is an event=link line with t, node, peer, sent, received and loss (text
// that is not a key=value pair, e.g. a logger's prefix, is skipped as ParseLogfmt does).
std::optional<LinkLine> ParseLinkLine(std::string_view line);

}  // namespace swarmbox::radio
