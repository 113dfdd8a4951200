// UdpProbe: one-way delay, loss, duplication and arrival order of UDP datagrams sent from one
// network namespace to another, measured by one process. The probe of the radio fault tests: the
// userspace mechanism on this host (netemd_e2e_test.cpp) and kernel netem inside a user-mode Linux
// guest (tests/orchestrator/netem_guest), so the two mechanisms are measured the same way.
//
// Both sockets live in this process (each created inside its namespace with setns), so send and
// arrival times come from one clock: each datagram carries its number and its CLOCK_REALTIME send
// time, and the receiver takes the kernel's arrival time (SO_TIMESTAMPNS), so its own wake-up
// latency does not count as delay.
//
//   ProbeOptions o{.from_netns = "ns-a", .to_netns = "ns-b", .to_addr = "10.213.7.2"};
//   o.count = 3000; o.spacing_us = 1000;                 // 3,000 datagrams, 1 ms apart
//   auto s = MeasureOneWay(o);
//   if (!s) return s.error();                            // a socket, bind or setns failed
//   double loss = 1.0 - double(s->received()) / s->sent;
//
// Not thread-safe with other setns() users of the calling thread (it switches the calling thread's
// network namespace while it creates the two sockets, and switches back).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/faults/command_runner.hpp"

namespace swarmbox::faults::testing {

struct ProbeArrival {
  std::uint32_t seq = 0;
  double delay_ms = 0.0;        // arrival - send [ms]
  std::int64_t arrived_us = 0;  // the kernel's arrival time, CLOCK_REALTIME [us]
};

struct ProbeSample {
  std::uint32_t sent = 0;              // datagrams sendto() took
  std::vector<std::uint32_t> seqs;     // the distinct numbers received, ascending
  std::vector<double> delay_ms;        // their one-way delays [ms] (a duplicated number: its last copy)
  std::uint32_t datagrams = 0;         // every datagram received, duplicates included
  std::vector<ProbeArrival> arrivals;  // every datagram received, in arrival order
  // The sender's worst lateness against its schedule [us]: how long this process (or, in a guest,
  // the guest) was not run; a stall delays the datagrams in flight by as much.
  std::int64_t max_send_late_us = 0;

  std::uint32_t received() const { return static_cast<std::uint32_t>(delay_ms.size()); }
  double Mean() const;
  double StdDev() const;            // the sample standard deviation (n - 1)
  double Quantile(double q) const;  // the value at floor(q x (n - 1)) of the sorted delays
};

struct ProbeOptions {
  std::string from_netns;  // names under /run/netns (ip netns add)
  std::string to_netns;
  std::string to_addr;  // the receiver binds this IPv4 address
  std::uint16_t port = 47001;
  int count = 0;
  std::int64_t spacing_us = 1000;  // between sends [us]; 0 = back to back
  std::size_t payload_bytes = 16;  // UDP payload [bytes], >= 16 (number + send time)
  std::int64_t quiet_us =
      1500000;  // the receiver stops after this long without a datagram after the last send
};

// kInvalidArgument for payload_bytes < 16 or count < 0; kIo when a namespace, socket or bind fails.
Result<ProbeSample> MeasureOneWay(const ProbeOptions& options);

// Packets a namespace's stack refused as malformed, from the text of /proc/net/snmp: Ip InHdrErrors
// (bad IP header checksum, version or length) plus Udp InErrors (bad UDP checksum or length).
std::int64_t SnmpReceiveErrors(std::string_view snmp);
// SnmpReceiveErrors of namespace `ns`, read with `ip netns exec NS cat /proc/net/snmp` through runner.
Result<std::int64_t> ReceiveErrors(CommandRunner& runner, const std::string& ns);

}  // namespace swarmbox::faults::testing
