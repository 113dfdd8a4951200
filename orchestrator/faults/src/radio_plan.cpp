#include "swarmbox/faults/radio_plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "swarmbox/faults/detail/number_format.hpp"
#include "swarmbox/faults/netemd_args.hpp"

namespace swarmbox::faults {
namespace {

using Argv = std::vector<std::string>;
constexpr const char* kUnlimitedRate = "10gbit";  // htb classes that only classify

std::string Ms(double ms) { return detail::FormatDecimal(ms, 3) + "ms"; }
std::string Percent(double fraction) { return detail::FormatDecimal(fraction * 100.0, 4) + "%"; }
std::string Kbit(double kbit) { return detail::FormatDecimal(kbit, 3) + "kbit"; }
std::string Hex(unsigned value) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%x", value);
  return buf;
}
std::string ClassId(std::size_t i) { return "1:" + Hex(static_cast<unsigned>(0x10 + i)); }
std::string NetemHandle(std::size_t i) { return Hex(static_cast<unsigned>(0x110 + i)) + ":"; }

Command Cmd(Argv argv) { return Command{std::move(argv), false}; }

Argv Tc(const std::string& dev, std::initializer_list<std::string> head, const Argv& tail = {}) {
  Argv argv = {"tc"};
  auto it = head.begin();
  // head = {"qdisc", "replace"} etc.; "dev IF" is inserted after the verb.
  argv.push_back(*it++);
  argv.push_back(*it++);
  argv.push_back("dev");
  argv.push_back(dev);
  for (; it != head.end(); ++it) argv.push_back(*it);
  argv.insert(argv.end(), tail.begin(), tail.end());
  return argv;
}

Argv Iptables(std::initializer_list<std::string> words) {
  Argv argv = {"iptables", "-w"};
  argv.insert(argv.end(), words.begin(), words.end());
  return argv;
}

Argv Nfqueue(unsigned queue) { return {"-j", "NFQUEUE", "--queue-num", std::to_string(queue), "--queue-bypass"}; }

Argv Concat(Argv a, const Argv& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

std::uint64_t DaemonSeed(std::uint64_t seed, const std::string& node, unsigned queue) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a over node and queue, mixed with the seed
  for (char c : node) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  h = (h ^ queue) * 1099511628211ULL;
  return (h ^ (seed * 0x9e3779b97f4a7c15ULL)) & 0x7fffffffffffffffULL;
}

struct Split {
  const RadioRule* all = nullptr;       // the all-traffic rule, if any
  std::vector<const RadioRule*> per;    // per-destination rules, in order
};

Result<Split> SplitRules(const std::vector<RadioRule>& rules, const LinkTarget& link) {
  Split s;
  if (rules.size() > kMaxRadioRules) {
    return Error(ErrorCode::kInvalidArgument,
                 "more than " + std::to_string(kMaxRadioRules) + " radio rules on one link");
  }
  for (const RadioRule& r : rules) {
    if (r.to.empty()) {
      if (s.all != nullptr) {
        return Error(ErrorCode::kInvalidArgument, "two rules without 'to' on one link", r.mark.ToString());
      }
      s.all = &r;
      continue;
    }
    for (const auto& peer : r.to) {
      if (link.peer_ipv4.find(peer) == link.peer_ipv4.end()) {
        return Error(ErrorCode::kInvalidArgument,
                     "no mesh address known for peer '" + peer + "' of " + link.node, r.mark.ToString());
      }
    }
    s.per.push_back(&r);
  }
  return s;
}

std::string PeerCidr(const LinkTarget& link, const std::string& peer) { return link.peer_ipv4.at(peer) + "/32"; }

void AddHtbTree(const std::string& dev, const Split& s, const LinkTarget& link, bool rate_only,
                std::vector<Command>* apply) {
  auto class_rate = [&](const RadioRule* r) -> Argv {
    if (rate_only && r != nullptr && r->spec.rate_kbit) {
      return {"rate", Kbit(*r->spec.rate_kbit), "ceil", Kbit(*r->spec.rate_kbit)};
    }
    return {"rate", kUnlimitedRate};
  };
  apply->push_back(Cmd(Tc(dev, {"qdisc", "replace", "root", "handle", "1:", "htb", "default", "1"})));
  apply->push_back(Cmd(Tc(dev, {"class", "replace", "parent", "1:", "classid", "1:1", "htb"}, class_rate(s.all))));
  if (!rate_only && s.all != nullptr) {
    apply->push_back(Cmd(Tc(dev, {"qdisc", "replace", "parent", "1:1", "handle", "100:", "netem"},
                            NetemOptions(s.all->spec, NetemLimitPackets(s.all->spec, link.link_rate_kbit)))));
  }
  for (std::size_t i = 0; i < s.per.size(); ++i) {
    const RadioRule& r = *s.per[i];
    apply->push_back(Cmd(Tc(dev, {"class", "replace", "parent", "1:", "classid", ClassId(i), "htb"}, class_rate(&r))));
    if (!rate_only) {
      apply->push_back(Cmd(Tc(dev, {"qdisc", "replace", "parent", ClassId(i), "handle", NetemHandle(i), "netem"},
                              NetemOptions(r.spec, NetemLimitPackets(r.spec, link.link_rate_kbit)))));
    }
    for (const auto& peer : r.to) {
      apply->push_back(Cmd(Tc(dev, {"filter", "add", "parent", "1:", "protocol", "ip", "prio", "1", "u32", "match",
                                    "ip", "dst", PeerCidr(link, peer), "flowid", ClassId(i)})));
    }
  }
}

RadioPlan PlanKernel(const Split& s, const LinkTarget& link) {
  RadioPlan plan;
  plan.mechanism = Mechanism::kKernelNetem;
  const std::string& dev = link.mesh_interface;
  if (s.per.empty()) {
    plan.apply.push_back(Cmd(Tc(dev, {"qdisc", "replace", "root", "netem"},
                                NetemOptions(s.all->spec, NetemLimitPackets(s.all->spec, link.link_rate_kbit)))));
  } else {
    AddHtbTree(dev, s, link, /*rate_only=*/false, &plan.apply);
  }
  plan.undo.push_back(Cmd(Tc(dev, {"qdisc", "del", "root"})));
  return plan;
}

// Rules whose packets go through swarmbox-netemd: delay, reorder, Gilbert-Elliott loss (drawn
// there; random loss stays with iptables statistic on ingress) or corruption (a bit flipped there).
bool Delays(const RadioRule* r) {
  return r != nullptr && (r->spec.has_delay() || r->spec.reorder > 0.0 || r->spec.gilbert_elliott.has_value() ||
                          r->spec.corrupt > 0.0);
}
bool Drops(const RadioRule* r) { return r != nullptr && r->spec.loss > 0.0; }
bool Duplicates(const RadioRule* r) { return r != nullptr && r->spec.duplicate > 0.0; }

// netem "duplicate P" for packets to `peer`: iptables TEE clones a fraction P (statistic) and sends
// the clone to the peer itself. The clone goes through OUTPUT again, where TEE leaves it alone
// (nf_dup_ipv4 does not duplicate a duplicate) and the rule's NFQUEUE gives it its own delay, as
// netem re-enqueues its clone.
Argv Tee(const std::string& chain, const LinkTarget& link, const std::string& peer, double p) {
  return Iptables({"-A", chain, "-d", PeerCidr(link, peer), "-m", "statistic", "--mode", "random", "--probability",
                   detail::FormatDecimal(p, 6), "-j", "TEE", "--gateway", link.peer_ipv4.at(peer)});
}

// Rate: tbf for all traffic, htb classes when there are per-destination rules; returns the undo.
std::vector<Command> PlanUserspaceRate(const Split& s, const LinkTarget& link, std::vector<Command>* apply) {
  const std::string& dev = link.mesh_interface;
  const bool any_rate = (s.all != nullptr && s.all->spec.rate_kbit) ||
                        std::any_of(s.per.begin(), s.per.end(), [](const RadioRule* r) { return r->spec.rate_kbit.has_value(); });
  if (!any_rate) return {};
  if (s.per.empty()) {
    const double rate_kbit = *s.all->spec.rate_kbit;
    const double burst_bytes = std::max(1600.0, std::ceil(rate_kbit * 1000.0 / 8.0 / 100.0));  // 10 ms
    apply->push_back(Cmd(Tc(dev, {"qdisc", "replace", "root", "tbf", "rate", Kbit(rate_kbit), "burst",
                                  detail::FormatDecimal(burst_bytes, 0), "latency", "500ms"})));
  } else {
    AddHtbTree(dev, s, link, /*rate_only=*/true, apply);
  }
  return {Cmd(Tc(dev, {"qdisc", "del", "root"}))};
}

// The swarmbox-netemd arguments of a delaying rule on `queue`.
NetemdArgs DelayDaemonArgs(const RadioRule& r, const LinkTarget& link, const RadioPlanOptions& o, unsigned queue) {
  NetemdArgs args;
  args.queue = static_cast<std::uint16_t>(queue);
  args.delay.delay_us = std::llround(r.spec.delay_ms * 1000.0);
  args.delay.jitter_us = std::llround(r.spec.jitter_ms * 1000.0);
  args.delay.distribution = r.spec.distribution;
  args.delay.correlation = r.spec.correlation;
  args.delay.reorder = r.spec.reorder;
  args.delay.reorder_correlation = r.spec.reorder_correlation;
  args.delay.reorder_gap = r.spec.reorder_gap;
  args.gilbert_elliott = r.spec.gilbert_elliott;
  args.corrupt = r.spec.corrupt;
  args.seed = DaemonSeed(o.seed, link.node, queue);
  args.queue_maxlen = std::min(NetemLimitPackets(r.spec, link.link_rate_kbit), kNetemdMaxQueueLen);
  args.pidfile = o.pid_dir + "/swarmbox-netemd-" + std::to_string(queue) + ".pid";
  args.daemonize = true;
  return args;
}

// Delay: one daemon per delaying rule, queue numbers in rule order (all-traffic rule first);
// *queue_of gets each delaying rule's queue. Returns the undo.
std::vector<Command> PlanDelayDaemons(const Split& s, const LinkTarget& link, const RadioPlanOptions& o,
                                      std::map<const RadioRule*, unsigned>* queue_of, std::vector<Command>* apply) {
  std::vector<Command> undo;
  std::vector<const RadioRule*> ordered;
  if (s.all != nullptr) ordered.push_back(s.all);
  ordered.insert(ordered.end(), s.per.begin(), s.per.end());
  for (std::size_t i = 0; i < ordered.size(); ++i) {
    const RadioRule* r = ordered[i];
    if (!Delays(r)) continue;
    const unsigned queue = o.first_queue + static_cast<unsigned>(i);
    (*queue_of)[r] = queue;
    const NetemdArgs args = DelayDaemonArgs(*r, link, o, queue);
    apply->push_back(Cmd(NetemdRunArgv(o.netemd, args)));
    undo.push_back(Cmd(NetemdStopArgv(o.netemd, args.pidfile)));
  }
  return undo;
}

// Egress chain: per-destination rules first (they win), the all-traffic rule last; a rule's
// duplication (TEE) before its NFQUEUE, since an accepted packet leaves the chain. Returns the undo.
std::vector<Command> PlanEgressChain(const Split& s, const LinkTarget& link,
                                     const std::map<const RadioRule*, unsigned>& queue_of, std::vector<Command>* apply) {
  const std::string& dev = link.mesh_interface;
  const std::string out_chain(kRadioChainOut);
  const bool any_duplicate = Duplicates(s.all) || std::any_of(s.per.begin(), s.per.end(), Duplicates);
  if (queue_of.empty() && !any_duplicate) return {};
  apply->push_back(Cmd(Iptables({"-N", out_chain})));
  for (const RadioRule* r : s.per) {
    for (const auto& peer : r->to) {
      if (Duplicates(r)) apply->push_back(Cmd(Tee(out_chain, link, peer, r->spec.duplicate)));
      Argv rule = Iptables({"-A", out_chain, "-d", PeerCidr(link, peer)});
      apply->push_back(Cmd(Delays(r) ? Concat(rule, Nfqueue(queue_of.at(r))) : Concat(rule, {"-j", "RETURN"})));
    }
  }
  if (Duplicates(s.all)) {
    // Unicast to each known peer (TEE needs a gateway); multicast and broadcast are not duplicated.
    for (const auto& [peer, ip] : link.peer_ipv4) apply->push_back(Cmd(Tee(out_chain, link, peer, s.all->spec.duplicate)));
  }
  if (Delays(s.all)) apply->push_back(Cmd(Concat(Iptables({"-A", out_chain}), Nfqueue(queue_of.at(s.all)))));
  apply->push_back(Cmd(Iptables({"-I", "OUTPUT", "-o", dev, "-j", out_chain})));
  return {Cmd(Iptables({"-D", "OUTPUT", "-o", dev, "-j", out_chain})), Cmd(Iptables({"-F", out_chain})),
          Cmd(Iptables({"-X", out_chain}))};
}

// Ingress chain: random loss with iptables statistic. Returns the undo.
std::vector<Command> PlanIngressChain(const Split& s, const LinkTarget& link, std::vector<Command>* apply) {
  const std::string& dev = link.mesh_interface;
  const std::string in_chain(kRadioChainIn);
  const bool any_loss = Drops(s.all) || std::any_of(s.per.begin(), s.per.end(), Drops);
  if (!any_loss) return {};
  auto drop = [](double p) -> Argv {
    return {"-m", "statistic", "--mode", "random", "--probability", detail::FormatDecimal(p, 6), "-j", "DROP"};
  };
  apply->push_back(Cmd(Iptables({"-N", in_chain})));
  for (const RadioRule* r : s.per) {
    for (const auto& peer : r->to) {
      Argv rule = Iptables({"-A", in_chain, "-s", PeerCidr(link, peer)});
      apply->push_back(Cmd(Drops(r) ? Concat(rule, drop(r->spec.loss)) : Concat(rule, {"-j", "RETURN"})));
    }
  }
  if (Drops(s.all)) apply->push_back(Cmd(Concat(Iptables({"-A", in_chain}), drop(s.all->spec.loss))));
  apply->push_back(Cmd(Iptables({"-I", "INPUT", "-i", dev, "-j", in_chain})));
  return {Cmd(Iptables({"-D", "INPUT", "-i", dev, "-j", in_chain})), Cmd(Iptables({"-F", in_chain})),
          Cmd(Iptables({"-X", in_chain}))};
}

RadioPlan PlanUserspace(const Split& s, const LinkTarget& link, const RadioPlanOptions& o) {
  RadioPlan plan;
  plan.mechanism = Mechanism::kUserspace;
  std::map<const RadioRule*, unsigned> queue_of;
  const std::vector<Command> undo_rate = PlanUserspaceRate(s, link, &plan.apply);
  const std::vector<Command> undo_daemons = PlanDelayDaemons(s, link, o, &queue_of, &plan.apply);
  const std::vector<Command> undo_out = PlanEgressChain(s, link, queue_of, &plan.apply);
  const std::vector<Command> undo_in = PlanIngressChain(s, link, &plan.apply);
  for (const auto* part : {&undo_in, &undo_out, &undo_daemons, &undo_rate}) {
    plan.undo.insert(plan.undo.end(), part->begin(), part->end());
  }
  return plan;
}

}  // namespace

std::uint32_t NetemLimitPackets(const NetemSpec& spec, double link_rate_kbit) {
  if (spec.limit_packets) return *spec.limit_packets;
  const double rate_kbit = spec.rate_kbit.value_or(link_rate_kbit);
  const double window_s = (spec.delay_ms + 4.0 * spec.jitter_ms) / 1000.0;
  const double packets = 2.0 * rate_kbit * 1000.0 / 8.0 * window_s / kAssumedPacketBytes;
  const double limit = std::max(static_cast<double>(kNetemDefaultLimit), std::ceil(packets));
  return static_cast<std::uint32_t>(std::min(limit, 1e7));
}

std::vector<std::string> NetemOptions(const NetemSpec& s, std::uint32_t limit_packets) {
  Argv o = {"limit", std::to_string(limit_packets)};
  if (s.has_delay()) {
    o.insert(o.end(), {"delay", Ms(s.delay_ms)});
    if (s.jitter_ms > 0.0) {
      o.push_back(Ms(s.jitter_ms));
      if (s.correlation > 0.0) o.push_back(Percent(s.correlation));
      // netem's default without a table is uniform; the tables are named for the others.
      if (s.distribution != DelayDistribution::kUniform) {
        o.insert(o.end(), {"distribution", std::string(DistributionName(s.distribution))});
      }
    }
  }
  if (s.gilbert_elliott) {
    const auto& g = *s.gilbert_elliott;
    o.insert(o.end(), {"loss", "gemodel", Percent(g.p), Percent(g.r), Percent(g.loss_bad), Percent(g.loss_good)});
  } else if (s.loss > 0.0) {
    o.insert(o.end(), {"loss", "random", Percent(s.loss)});
    if (s.loss_correlation > 0.0) o.push_back(Percent(s.loss_correlation));
  }
  if (s.duplicate > 0.0) o.insert(o.end(), {"duplicate", Percent(s.duplicate)});
  if (s.corrupt > 0.0) o.insert(o.end(), {"corrupt", Percent(s.corrupt)});
  if (s.reorder > 0.0) {
    o.insert(o.end(), {"reorder", Percent(s.reorder)});
    if (s.reorder_correlation > 0.0) o.push_back(Percent(s.reorder_correlation));
    if (s.reorder_gap > 0) o.insert(o.end(), {"gap", std::to_string(s.reorder_gap)});
  }
  if (s.rate_kbit) o.insert(o.end(), {"rate", Kbit(*s.rate_kbit)});
  return o;
}

Result<RadioPlan> PlanRadio(const std::vector<RadioRule>& rules, const LinkTarget& link, Mechanism mechanism,
                            const RadioPlanOptions& options) {
  if (link.mesh_interface.empty()) {
    return Error(ErrorCode::kInvalidArgument, "no mesh interface given for " + link.node);
  }
  RadioPlan empty;
  empty.mechanism = mechanism;
  if (rules.empty()) return empty;
  SWARMBOX_TRY(CheckMechanismSupports(rules, mechanism));
  auto split = SplitRules(rules, link);
  if (!split) return split.error();
  if (mechanism == Mechanism::kKernelNetem) return PlanKernel(*split, link);
  if (static_cast<std::size_t>(options.first_queue) + rules.size() > 65536) {
    return Error(ErrorCode::kInvalidArgument, "NFQUEUE numbers past 65535");
  }
  return PlanUserspace(*split, link, options);
}

Result<RadioPlan> PlanRadioChange(const std::vector<RadioRule>& from, const std::vector<RadioRule>& to,
                                  const LinkTarget& link, Mechanism mechanism, const RadioPlanOptions& options) {
  auto old_plan = PlanRadio(from, link, mechanism, options);
  if (!old_plan) return old_plan.error();
  auto new_plan = PlanRadio(to, link, mechanism, options);
  if (!new_plan) return new_plan.error();
  RadioPlan change;
  change.mechanism = mechanism;
  change.apply = old_plan->undo;
  change.apply.insert(change.apply.end(), new_plan->apply.begin(), new_plan->apply.end());
  change.undo = new_plan->undo;
  return change;
}

std::vector<RadioRule> ComposeRadio(const std::vector<RadioRule>& base, const std::vector<RadioRule>& overlay) {
  const bool overlay_all = std::any_of(overlay.begin(), overlay.end(), [](const RadioRule& r) { return r.to.empty(); });
  if (overlay_all || base.empty()) return overlay.empty() ? base : overlay;
  std::set<std::string> taken;
  for (const auto& r : overlay) taken.insert(r.to.begin(), r.to.end());
  std::vector<RadioRule> out;
  for (RadioRule r : base) {
    if (!r.to.empty()) {
      std::erase_if(r.to, [&](const std::string& peer) { return taken.count(peer) != 0; });
      if (r.to.empty()) continue;
    }
    out.push_back(std::move(r));
  }
  out.insert(out.end(), overlay.begin(), overlay.end());
  return out;
}

}  // namespace swarmbox::faults
