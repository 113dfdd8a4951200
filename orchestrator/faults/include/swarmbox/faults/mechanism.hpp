// Mechanism: how a NetemSpec is carried out on a host, detected once per host.
//
//   kKernelNetem  tc qdisc replace ... netem (and htb + u32 filters for per-destination rules)
//   kUserspace    where the kernel has no sch_netem ("Specified qdisc kind is unknown"; WSL2,
//                 minikube, some cloud kernels, this project's machines): swarmbox-netemd on an
//                 iptables NFQUEUE (delay, jitter, distribution, correlation, reordering,
//                 Gilbert-Elliott loss drawn per packet, corruption: one bit flipped), iptables
//                 `statistic` on INPUT for random loss, `statistic` + TEE on OUTPUT for
//                 duplication (unicast to known peers), tbf (or htb classes per destination) for
//                 rate. Refused here (it cannot): loss_correlation.
//
//   MechanismCache cache;
//   auto m = cache.Get(host, [&] { return DetectMechanism(sidecar_runner); });
//   if (!m) return m.error();                                  // tc failed for another reason
//   SWARMBOX_TRY(CheckMechanismSupports(rules, *m));            // refuse before the trial starts
#pragma once

#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/faults/command_runner.hpp"
#include "swarmbox/faults/netem_spec.hpp"

namespace swarmbox::faults {

enum class Mechanism { kKernelNetem, kUserspace };

// "netem" or "userspace-nfqueue": the value written to events.jsonl.
std::string_view MechanismName(Mechanism mechanism);

// tc's message when the kernel lacks sch_netem.
inline constexpr std::string_view kNoNetemMessage = "Specified qdisc kind is unknown";
// The probe interface: the loopback of the namespace the probe runs in (never the mesh or sim link).
inline constexpr std::string_view kProbeInterface = "lo";

// The probe: put a zero-delay netem on `iface`, then remove it (the removal may fail when the
// first command did).
std::vector<Command> NetemProbeCommands(std::string_view iface = kProbeInterface);
// From the probe's first command: exit 0 -> kKernelNetem; tc's stderr containing kNoNetemMessage
// -> kUserspace; anything else is kUnavailable with tc's message (no NET_ADMIN, no tc...).
Result<Mechanism> ClassifyNetemProbe(const CommandOutput& probe);
// Runs the probe through `runner` and classifies it.
Result<Mechanism> DetectMechanism(CommandRunner& runner, std::string_view iface = kProbeInterface);

// Whether `mechanism` can honour every rule; the error names the first key it cannot do and why
// (kInvalidArgument at the rule's file:line:col). Kernel netem honours every valid spec.
Status CheckMechanismSupports(const std::vector<RadioRule>& rules, Mechanism mechanism);

// Detection once per host, thread-safe. A failed detection is not cached.
class MechanismCache {
 public:
  Result<Mechanism> Get(const std::string& host, const std::function<Result<Mechanism>()>& detect);

 private:
  std::mutex mu_;
  std::map<std::string, Mechanism> known_;
};

}  // namespace swarmbox::faults
