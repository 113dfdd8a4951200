#include "swarmbox/faults/mechanism.hpp"

namespace swarmbox::faults {

std::string_view MechanismName(Mechanism mechanism) {
  return mechanism == Mechanism::kKernelNetem ? "netem" : "userspace-nfqueue";
}

std::vector<Command> NetemProbeCommands(std::string_view iface) {
  const std::string dev(iface);
  return {
      Command{{"tc", "qdisc", "replace", "dev", dev, "root", "netem", "delay", "0ms"}, false},
      Command{{"tc", "qdisc", "del", "dev", dev, "root"}, true},
  };
}

Result<Mechanism> ClassifyNetemProbe(const CommandOutput& probe) {
  if (probe.exit_code == 0) return Mechanism::kKernelNetem;
  if (probe.stderr_text.find(kNoNetemMessage) != std::string::npos) return Mechanism::kUserspace;
  std::string err = probe.stderr_text;
  while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
  return Error(ErrorCode::kUnavailable,
               "cannot tell whether the kernel has sch_netem: the tc probe exited " +
                   std::to_string(probe.exit_code) + (err.empty() ? "" : ": " + err),
               "tc qdisc replace dev lo root netem delay 0ms");
}

Result<Mechanism> DetectMechanism(CommandRunner& runner, std::string_view iface) {
  const auto probe = NetemProbeCommands(iface);
  auto out = runner.Run(probe[0].argv);
  if (!out) return out.error().Context("probing for sch_netem");
  auto mechanism = ClassifyNetemProbe(*out);
  if (mechanism && *mechanism == Mechanism::kKernelNetem) {
    // Leave the probe interface as it was; a failure here is harmless but reported.
    auto undo = runner.Run(probe[1].argv);
    if (!undo) return undo.error().Context("removing the sch_netem probe");
  }
  return mechanism;
}

Status CheckMechanismSupports(const std::vector<RadioRule>& rules, Mechanism mechanism) {
  if (mechanism == Mechanism::kKernelNetem) return Ok{};
  for (const RadioRule& rule : rules) {
    const NetemSpec& s = rule.spec;
    auto refuse = [&](std::string_view key, std::string_view why) {
      return Error(ErrorCode::kInvalidArgument,
                   "'" + std::string(key) + "' cannot be honoured on this host: the kernel has no "
                   "sch_netem and the userspace mechanism " + std::string(why),
                   rule.mark.ToString());
    };
    if (s.loss_correlation > 0.0) {
      return refuse("loss_correlation", "draws each loss independently with iptables statistic");
    }
  }
  return Ok{};
}

Result<Mechanism> MechanismCache::Get(const std::string& host,
                                      const std::function<Result<Mechanism>()>& detect) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (auto it = known_.find(host); it != known_.end()) return it->second;
  }
  auto m = detect();
  if (!m) return m.error();
  std::lock_guard<std::mutex> lock(mu_);
  known_.emplace(host, *m);
  return *m;
}

}  // namespace swarmbox::faults
