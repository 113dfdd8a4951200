#include "guest_lab.hpp"

#include "guest_console.hpp"

namespace swarmbox::netem_guest {
namespace {

constexpr const char* kMacA = "02:5b:00:00:00:0a";
constexpr const char* kMacB = "02:5b:00:00:00:0b";

}  // namespace

Result<faults::CommandOutput> ReportingRunner::Run(const std::vector<std::string>& argv) {
  auto out = inner_.Run(argv);
  Fields f = {{"scenario", scenario_}, {"drone", node_}, {"argv", faults::CommandText(argv)}};
  if (out) {
    f.emplace_back("exit", std::to_string(out->exit_code));
    if (out->exit_code != 0) f.emplace_back("stderr", out->stderr_text);
  } else {
    f.emplace_back("error", out.error().ToString());
  }
  reporter_.Record(kEventApplied, f);
  return out;
}

GuestLab::GuestLab(faults::CommandRunner& runner, Reporter& reporter, std::string scenario)
    : runner_(runner), reporter_(reporter), scenario_(std::move(scenario)) {
  in_a_ = std::make_unique<faults::PrefixCommandRunner>(
      runner_, std::vector<std::string>{"ip", "netns", "exec", Namespace("a")});
  in_b_ = std::make_unique<faults::PrefixCommandRunner>(
      runner_, std::vector<std::string>{"ip", "netns", "exec", Namespace("b")});
  report_a_ = std::make_unique<ReportingRunner>(*in_a_, reporter_, scenario_, "a");
  report_b_ = std::make_unique<ReportingRunner>(*in_b_, reporter_, scenario_, "b");
}

GuestLab::~GuestLab() {
  if (!created_) return;
  (void)runner_.Run({"ip", "netns", "del", Namespace("a")});
  (void)runner_.Run({"ip", "netns", "del", Namespace("b")});
}

Status GuestLab::Must(const std::vector<std::string>& argv) {
  auto out = runner_.Run(argv);
  if (!out) return out.error();
  if (out->exit_code != 0) {
    return Error(ErrorCode::kInternal, "`" + faults::CommandText(argv) + "` exited " +
                                           std::to_string(out->exit_code) + ": " + out->stderr_text);
  }
  return Ok{};
}

Status GuestLab::Create() {
  const std::string a = Namespace("a"), b = Namespace("b");
  const std::string if_a = Interface("a"), if_b = Interface("b");
  SWARMBOX_TRY(Must({"ip", "netns", "add", a}));
  created_ = true;
  SWARMBOX_TRY(Must({"ip", "netns", "add", b}));
  SWARMBOX_TRY(Must({"ip", "link", "add", if_a, "address", kMacA, "netns", a, "type", "veth", "peer", "name",
                     if_b, "address", kMacB, "netns", b}));
  SWARMBOX_TRY(Must({"ip", "-n", a, "addr", "add", std::string(kAddrA) + "/24", "dev", if_a}));
  SWARMBOX_TRY(Must({"ip", "-n", b, "addr", "add", std::string(kAddrB) + "/24", "dev", if_b}));
  SWARMBOX_TRY(Must({"ip", "-n", b, "addr", "add", std::string(kAddrC) + "/24", "dev", if_b}));
  for (const auto& [ns, dev] : {std::pair{a, if_a}, std::pair{b, if_b}}) {
    SWARMBOX_TRY(Must({"ip", "-n", ns, "link", "set", "lo", "up"}));
    SWARMBOX_TRY(Must({"ip", "-n", ns, "link", "set", dev, "up"}));
  }
  SWARMBOX_TRY(
      Must({"ip", "-n", a, "neigh", "replace", kAddrB, "lladdr", kMacB, "nud", "permanent", "dev", if_a}));
  SWARMBOX_TRY(
      Must({"ip", "-n", a, "neigh", "replace", kAddrC, "lladdr", kMacB, "nud", "permanent", "dev", if_a}));
  SWARMBOX_TRY(
      Must({"ip", "-n", b, "neigh", "replace", kAddrA, "lladdr", kMacA, "nud", "permanent", "dev", if_b}));
  return Ok{};
}

faults::CommandRunner& GuestLab::In(const std::string& node) { return node == "a" ? *report_a_ : *report_b_; }

faults::LinkTarget GuestLab::Link(const std::string& node) const {
  if (node == "a")
    return faults::LinkTarget{
        "a", Interface("a"), {{"b", kAddrB}, {"c", kAddrC}}, faults::kAssumedLinkRateKbit};
  return faults::LinkTarget{"b", Interface("b"), {{"a", kAddrA}}, faults::kAssumedLinkRateKbit};
}

std::vector<faults::MeshNode> GuestLab::MeshNodes() const {
  return {{"a", Interface("a"), kAddrA}, {"b", Interface("b"), kAddrB}};
}

Result<std::string> GuestLab::Tree(const std::string& node) {
  std::string text;
  for (const char* what : {"qdisc", "class", "filter"}) {
    const std::vector<std::string> argv = {"ip", "netns", "exec", Namespace(node), "tc",
                                           what, "show",  "dev",  Interface(node)};
    auto out = runner_.Run(argv);
    if (!out) return out.error();
    if (out->exit_code != 0)
      return Error(ErrorCode::kInternal, "`" + faults::CommandText(argv) + "`: " + out->stderr_text);
    text += out->stdout_text;
  }
  return text;
}

Result<std::string> GuestLab::IptablesRules(const std::string& node) {
  const std::vector<std::string> argv = {"ip", "netns", "exec", Namespace(node), "iptables", "-w", "-S"};
  auto out = runner_.Run(argv);
  if (!out) return out.error();
  if (out->exit_code != 0)
    return Error(ErrorCode::kInternal, "`" + faults::CommandText(argv) + "`: " + out->stderr_text);
  return out->stdout_text;
}

Result<std::int64_t> GuestLab::ReceiveErrors(const std::string& node) {
  return faults::testing::ReceiveErrors(runner_, Namespace(node));
}

Result<faults::testing::ProbeSample> GuestLab::Measure(const std::string& peer, int count,
                                                       std::int64_t spacing_us, std::size_t payload_bytes) {
  faults::testing::ProbeOptions o;
  o.from_netns = Namespace("a");
  o.to_netns = Namespace("b");
  o.to_addr = peer == "c" ? kAddrC : kAddrB;
  o.port = kPort;
  o.count = count;
  o.spacing_us = spacing_us;
  o.payload_bytes = payload_bytes;
  o.quiet_us = kQuietUs;
  return faults::testing::MeasureOneWay(o);
}

}  // namespace swarmbox::netem_guest
