// GuestLab: the network the netem guest measures on, built inside the guest kernel, and the
// reporter its scenarios write to.
//
//   namespace a: veth-a 10.213.7.1/24 (drone "a")
//   namespace b: veth-b 10.213.7.2/24 (drone "b") and 10.213.7.3/24 (drone "c", a second peer
//                behind the same link, for per-destination rules)
//
// The MAC addresses are fixed and both sides get permanent neighbour entries, so ARP never crosses
// the impaired link: the probe measures the qdisc, as the userspace test (where iptables never
// sees ARP) does. Drones "a" and "b" are the radio's nodes (their namespaces stand for the
// agents' sidecars); "c" is an address only.
//
//   PosixCommandRunner posix;
//   GuestLab lab(posix);
//   SWARMBOX_TRY(lab.Create());                     // ~GuestLab deletes the namespaces
//   auto s = lab.Measure("c", 300, 2000);           // a -> c, 300 datagrams 2 ms apart
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "guest_measurements.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/faults/posix_command_runner.hpp"
#include "swarmbox/faults/partition_plan.hpp"
#include "swarmbox/faults/radio_plan.hpp"
#include "udp_probe.hpp"

namespace swarmbox::netem_guest {

// Where scenario records go (the console in the guest; a vector in tests).
class Reporter {
 public:
  virtual ~Reporter() = default;
  virtual void Record(std::string_view event, const Fields& fields) = 0;
};

// Runs through `inner` and reports each argv (event=applied scenario= drone= argv= exit=) first.
class ReportingRunner : public faults::CommandRunner {
 public:
  ReportingRunner(faults::CommandRunner& inner, Reporter& reporter, std::string scenario, std::string node)
      : inner_(inner), reporter_(reporter), scenario_(std::move(scenario)), node_(std::move(node)) {}
  Result<faults::CommandOutput> Run(const std::vector<std::string>& argv) override;

 private:
  faults::CommandRunner& inner_;
  Reporter& reporter_;
  std::string scenario_;
  std::string node_;
};

class GuestLab {
 public:
  static constexpr const char* kAddrA = "10.213.7.1";
  static constexpr const char* kAddrB = "10.213.7.2";
  static constexpr const char* kAddrC = "10.213.7.3";
  static constexpr std::uint16_t kPort = 47001;
  // UDP payload + UDP (8) + IPv4 (20) + Ethernet (14) headers: the bytes netem's rate counts.
  static constexpr std::size_t kHeaderBytes = 8 + 20 + 14;
  // The probe stops 0.5 s after the last datagram (every scenario's delays are under 0.1 s; the
  // rate probes keep arriving until their queue is empty).
  static constexpr std::int64_t kQuietUs = 500000;

  GuestLab(faults::CommandRunner& runner, Reporter& reporter, std::string scenario);
  GuestLab(const GuestLab&) = delete;
  GuestLab& operator=(const GuestLab&) = delete;
  ~GuestLab();  // deletes the namespaces it created (best effort)

  Status Create();

  // Commands inside node "a" or "b"'s namespace (reported as they run).
  faults::CommandRunner& In(const std::string& node);
  // The radio link of "a" (peers b and c) or "b" (peer a), as the injector describes an agent's.
  faults::LinkTarget Link(const std::string& node) const;
  std::vector<faults::MeshNode> MeshNodes() const;
  std::vector<std::string> RadioNodes() const { return {"a", "b"}; }
  std::vector<std::string> Drones() const { return {"a", "b", "c"}; }

  // tc qdisc, class and filter listings of the node's veth.
  Result<std::string> Tree(const std::string& node);
  // iptables -S in the node's namespace.
  Result<std::string> IptablesRules(const std::string& node);
  // Ip InHdrErrors + Udp InErrors of the node's namespace.
  Result<std::int64_t> ReceiveErrors(const std::string& node);

  // Datagrams from a to `peer` ("b" or "c"): `count`, `spacing_us` apart, `payload_bytes` each.
  Result<faults::testing::ProbeSample> Measure(const std::string& peer, int count, std::int64_t spacing_us,
                                               std::size_t payload_bytes = 16);

  Reporter& reporter() { return reporter_; }
  const std::string& scenario() const { return scenario_; }

 private:
  Status Must(const std::vector<std::string>& argv);
  std::string Namespace(const std::string& node) const { return "sbg-" + node; }
  std::string Interface(const std::string& node) const { return "veth-" + node; }

  faults::CommandRunner& runner_;
  Reporter& reporter_;
  std::string scenario_;
  bool created_ = false;
  std::unique_ptr<faults::PrefixCommandRunner> in_a_, in_b_;
  std::unique_ptr<ReportingRunner> report_a_, report_b_;
};

}  // namespace swarmbox::netem_guest
