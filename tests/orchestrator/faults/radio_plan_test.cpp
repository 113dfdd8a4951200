#include "swarmbox/faults/radio_plan.hpp"

#include <algorithm>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "swarmbox/faults/netemd_args.hpp"
#include "test_util.hpp"

namespace swarmbox::faults {
namespace {

using ::testing::ElementsAre;
using testing::Lines;
using testing::Yaml;

std::vector<RadioRule> Rules(const std::string& yaml) {
  auto rules = ParseRadioRules(Yaml(yaml), "radio");
  EXPECT_TRUE(rules) << rules.error().ToString();
  return rules ? *rules : std::vector<RadioRule>{};
}

LinkTarget Link() {
  return LinkTarget{"scout_1", "eth1", {{"scout_2", "10.77.2.11"}, {"lifter", "10.77.2.12"}, {"scout_3", "10.77.2.13"}}};
}

// --- kernel netem ---------------------------------------------------------------------------------

TEST(RadioPlan, KernelNetemUsesReplaceWithEveryOption) {
  auto plan = PlanRadio(Rules("{delay_ms: 100, jitter_ms: 20, distribution: normal, correlation: 0.25, loss: 0.05,"
                              " loss_correlation: 0.1, duplicate: 0.01, corrupt: 0.001, reorder: 0.2,"
                              " reorder_correlation: 0.5, reorder_gap: 5, rate_kbit: 2000}"),
                        Link(), Mechanism::kKernelNetem);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_EQ(plan->mechanism, Mechanism::kKernelNetem);
  EXPECT_THAT(Lines(plan->apply),
              ElementsAre("tc qdisc replace dev eth1 root netem limit 1000 delay 100ms 20ms 25% distribution normal "
                          "loss random 5% 10% duplicate 1% corrupt 0.1% reorder 20% 50% gap 5 rate 2000kbit"));
  EXPECT_THAT(Lines(plan->undo), ElementsAre("tc qdisc del dev eth1 root"));
}

TEST(RadioPlan, KernelNetemUniformJitterNamesNoTable) {
  auto plan = PlanRadio(Rules("{delay_ms: 50, jitter_ms: 10, rate_kbit: 500}"), Link(), Mechanism::kKernelNetem);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_THAT(Lines(plan->apply), ElementsAre("tc qdisc replace dev eth1 root netem limit 1000 delay 50ms 10ms rate 500kbit"));
}

TEST(RadioPlan, KernelNetemGilbertElliottLoss) {
  auto plan = PlanRadio(Rules("{gilbert_elliott: {p: 0.05, r: 0.5, loss_bad: 0.9, loss_good: 0.01}}"), Link(),
                        Mechanism::kKernelNetem);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_THAT(Lines(plan->apply),
              ElementsAre("tc qdisc replace dev eth1 root netem limit 1000 loss gemodel 5% 50% 90% 1%"));
}

TEST(RadioPlan, LimitIsRaisedWhenDelayTimesRateNeedsIt) {
  // 2 x 100,000 kbit/s x (200 ms + 4 x 50 ms) / 128 B = 2 x 12.5e6 B/s x 0.4 s / 128 B = 78,125 packets.
  auto plan = PlanRadio(Rules("{delay_ms: 200, jitter_ms: 50}"), Link(), Mechanism::kKernelNetem);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_THAT(Lines(plan->apply), ElementsAre("tc qdisc replace dev eth1 root netem limit 78125 delay 200ms 50ms"));
}

TEST(RadioPlan, NetemLimitFollowsTheFormula) {
  NetemSpec slow;
  slow.delay_ms = 100;
  slow.rate_kbit = 1000;  // 2 x 125,000 B/s x 0.1 s / 128 B = 195.3 -> the default 1000 stays
  EXPECT_EQ(NetemLimitPackets(slow), kNetemDefaultLimit);
  NetemSpec fast;
  fast.delay_ms = 500;
  fast.rate_kbit = 10000;  // 2 x 1.25e6 B/s x 0.5 s / 128 B = 9765.6 -> 9766
  EXPECT_EQ(NetemLimitPackets(fast), 9766u);
  fast.limit_packets = 300;  // an explicit limit wins
  EXPECT_EQ(NetemLimitPackets(fast), 300u);
  NetemSpec loss_only;
  loss_only.loss = 0.1;
  EXPECT_EQ(NetemLimitPackets(loss_only), kNetemDefaultLimit);
}

TEST(RadioPlan, KernelPerDestinationRulesUseHtbAndU32Filters) {
  auto plan = PlanRadio(Rules("rules:\n"
                              "  - {loss: 0.01}\n"
                              "  - {to: [scout_2], delay_ms: 300}\n"
                              "  - {to: [lifter, scout_3], loss: 0.3}\n"),
                        Link(), Mechanism::kKernelNetem);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_THAT(Lines(plan->apply),
              ElementsAre("tc qdisc replace dev eth1 root handle 1: htb default 1",
                          "tc class replace dev eth1 parent 1: classid 1:1 htb rate 10gbit",
                          "tc qdisc replace dev eth1 parent 1:1 handle 100: netem limit 1000 loss random 1%",
                          "tc class replace dev eth1 parent 1: classid 1:10 htb rate 10gbit",
                          "tc qdisc replace dev eth1 parent 1:10 handle 110: netem limit 58594 delay 300ms",
                          "tc filter add dev eth1 parent 1: protocol ip prio 1 u32 match ip dst 10.77.2.11/32 flowid 1:10",
                          "tc class replace dev eth1 parent 1: classid 1:11 htb rate 10gbit",
                          "tc qdisc replace dev eth1 parent 1:11 handle 111: netem limit 1000 loss random 30%",
                          "tc filter add dev eth1 parent 1: protocol ip prio 1 u32 match ip dst 10.77.2.12/32 flowid 1:11",
                          "tc filter add dev eth1 parent 1: protocol ip prio 1 u32 match ip dst 10.77.2.13/32 flowid 1:11"));
  EXPECT_THAT(Lines(plan->undo), ElementsAre("tc qdisc del dev eth1 root"));
}

TEST(RadioPlan, KernelPerDestinationWithoutAllTrafficRuleLeavesTheDefaultClassBare) {
  auto plan = PlanRadio(Rules("{to: [lifter], delay_ms: 10}"), Link(), Mechanism::kKernelNetem);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_THAT(Lines(plan->apply),
              ElementsAre("tc qdisc replace dev eth1 root handle 1: htb default 1",
                          "tc class replace dev eth1 parent 1: classid 1:1 htb rate 10gbit",
                          "tc class replace dev eth1 parent 1: classid 1:10 htb rate 10gbit",
                          "tc qdisc replace dev eth1 parent 1:10 handle 110: netem limit 1954 delay 10ms",
                          "tc filter add dev eth1 parent 1: protocol ip prio 1 u32 match ip dst 10.77.2.12/32 flowid 1:10"));
}

// --- userspace ------------------------------------------------------------------------------------

TEST(RadioPlan, UserspaceDelayJitterLossAndRate) {
  RadioPlanOptions options;
  options.first_queue = 4;
  options.seed = 42;
  auto plan = PlanRadio(Rules("{delay_ms: 50, jitter_ms: 10, distribution: pareto, correlation: 0.25, loss: 0.05,"
                              " reorder: 0.1, rate_kbit: 800}"),
                        Link(), Mechanism::kUserspace, options);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_EQ(plan->mechanism, Mechanism::kUserspace);
  ASSERT_EQ(plan->apply.size(), 8u);
  EXPECT_THAT(Lines(plan->apply),
              ElementsAre("tc qdisc replace dev eth1 root tbf rate 800kbit burst 1600 latency 500ms",
                          ::testing::StartsWith("/usr/bin/swarmbox-netemd run --queue 4 --delay-us 50000 "
                                                "--jitter-us 10000 --distribution pareto --correlation 0.25 "
                                                "--reorder 0.1 --reorder-correlation 0 --reorder-gap 0 --seed "),
                          "iptables -w -N SWARMBOX-RADIO-OUT",
                          "iptables -w -A SWARMBOX-RADIO-OUT -j NFQUEUE --queue-num 4 --queue-bypass",
                          "iptables -w -I OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT",
                          "iptables -w -N SWARMBOX-RADIO-IN",
                          "iptables -w -A SWARMBOX-RADIO-IN -m statistic --mode random --probability 0.05 -j DROP",
                          "iptables -w -I INPUT -i eth1 -j SWARMBOX-RADIO-IN"));
  EXPECT_THAT(plan->apply[1].argv,
              ::testing::IsSupersetOf({std::string("--queue-maxlen"), std::string("1000"), std::string("--pidfile"),
                                       std::string("/run/swarmbox-netemd-4.pid"), std::string("--daemonize")}));
  EXPECT_THAT(Lines(plan->undo),
              ElementsAre("iptables -w -D INPUT -i eth1 -j SWARMBOX-RADIO-IN",
                          "iptables -w -F SWARMBOX-RADIO-IN",
                          "iptables -w -X SWARMBOX-RADIO-IN",
                          "iptables -w -D OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT",
                          "iptables -w -F SWARMBOX-RADIO-OUT",
                          "iptables -w -X SWARMBOX-RADIO-OUT",
                          "/usr/bin/swarmbox-netemd stop --pidfile /run/swarmbox-netemd-4.pid",
                          "tc qdisc del dev eth1 root"));
}

TEST(RadioPlan, UserspaceQueueLengthIsCappedAtTheDaemonsMaximum) {
  // 2 x 100,000 kbit/s x 60 s / 128 B = 11.7 million packets: netem's limit may be that, the
  // daemon's queue is capped.
  auto plan = PlanRadio(Rules("{delay_ms: 60000}"), Link(), Mechanism::kUserspace);
  ASSERT_TRUE(plan) << plan.error().ToString();
  const auto& argv = plan->apply[0].argv;
  auto it = std::find(argv.begin(), argv.end(), "--queue-maxlen");
  ASSERT_NE(it, argv.end());
  EXPECT_EQ(*(it + 1), std::to_string(kNetemdMaxQueueLen));
}

TEST(RadioPlan, UserspaceLossOnlyNeedsNoDaemon) {
  auto plan = PlanRadio(Rules("{loss: 0.1}"), Link(), Mechanism::kUserspace);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_THAT(Lines(plan->apply),
              ElementsAre("iptables -w -N SWARMBOX-RADIO-IN",
                          "iptables -w -A SWARMBOX-RADIO-IN -m statistic --mode random --probability 0.1 -j DROP",
                          "iptables -w -I INPUT -i eth1 -j SWARMBOX-RADIO-IN"));
  EXPECT_THAT(Lines(plan->undo),
              ElementsAre("iptables -w -D INPUT -i eth1 -j SWARMBOX-RADIO-IN", "iptables -w -F SWARMBOX-RADIO-IN",
                          "iptables -w -X SWARMBOX-RADIO-IN"));
}

TEST(RadioPlan, UserspaceGilbertElliottLossIsDrawnByTheDaemonOnEgress) {
  // Bursty loss has state, which iptables statistic has not: the daemon drops, so the rule's packets
  // go through its queue even without delay, and no ingress chain is made.
  auto plan = PlanRadio(Rules("{gilbert_elliott: {p: 0.02, r: 0.25, loss_bad: 0.9, loss_good: 0.01}}"), Link(),
                        Mechanism::kUserspace);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_THAT(Lines(plan->apply),
              ElementsAre(::testing::AllOf(::testing::StartsWith("/usr/bin/swarmbox-netemd run --queue 0 --delay-us 0 "),
                                           ::testing::EndsWith("--daemonize --ge-p 0.02 --ge-r 0.25 --ge-loss-bad 0.9 "
                                                               "--ge-loss-good 0.01")),
                          "iptables -w -N SWARMBOX-RADIO-OUT",
                          "iptables -w -A SWARMBOX-RADIO-OUT -j NFQUEUE --queue-num 0 --queue-bypass",
                          "iptables -w -I OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT"));
  EXPECT_THAT(Lines(plan->undo),
              ElementsAre("iptables -w -D OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT", "iptables -w -F SWARMBOX-RADIO-OUT",
                          "iptables -w -X SWARMBOX-RADIO-OUT",
                          "/usr/bin/swarmbox-netemd stop --pidfile /run/swarmbox-netemd-0.pid"));
}

TEST(RadioPlan, UserspaceCorruptionIsDoneByTheDaemonOnEgress) {
  // netem "corrupt 10%": the daemon flips one bit of the chosen packets, so the rule's packets go
  // through its queue even without delay; random loss still goes to the ingress chain.
  auto plan = PlanRadio(Rules("{corrupt: 0.1, loss: 0.05}"), Link(), Mechanism::kUserspace);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_THAT(Lines(plan->apply),
              ElementsAre(::testing::AllOf(::testing::StartsWith("/usr/bin/swarmbox-netemd run --queue 0 --delay-us 0 "),
                                           ::testing::EndsWith("--daemonize --corrupt 0.1")),
                          "iptables -w -N SWARMBOX-RADIO-OUT",
                          "iptables -w -A SWARMBOX-RADIO-OUT -j NFQUEUE --queue-num 0 --queue-bypass",
                          "iptables -w -I OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT",
                          "iptables -w -N SWARMBOX-RADIO-IN",
                          "iptables -w -A SWARMBOX-RADIO-IN -m statistic --mode random --probability 0.05 -j DROP",
                          "iptables -w -I INPUT -i eth1 -j SWARMBOX-RADIO-IN"));
  EXPECT_THAT(Lines(plan->undo),
              ElementsAre("iptables -w -D INPUT -i eth1 -j SWARMBOX-RADIO-IN", "iptables -w -F SWARMBOX-RADIO-IN",
                          "iptables -w -X SWARMBOX-RADIO-IN", "iptables -w -D OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT",
                          "iptables -w -F SWARMBOX-RADIO-OUT", "iptables -w -X SWARMBOX-RADIO-OUT",
                          "/usr/bin/swarmbox-netemd stop --pidfile /run/swarmbox-netemd-0.pid"));
}

TEST(RadioPlan, UserspaceDuplicationTeesToEachPeerBeforeTheQueue) {
  // netem "duplicate 10%" for all traffic: one TEE per known peer (the clone is routed to the peer
  // itself), before the NFQUEUE so the clone comes back through it for its own delay.
  auto plan = PlanRadio(Rules("{delay_ms: 5, duplicate: 0.1}"), Link(), Mechanism::kUserspace);
  ASSERT_TRUE(plan) << plan.error().ToString();
  const std::vector<std::string> lines = Lines(plan->apply);
  ASSERT_EQ(lines.size(), 7u);
  EXPECT_THAT(lines[0], ::testing::StartsWith("/usr/bin/swarmbox-netemd run --queue 0 --delay-us 5000 "));
  EXPECT_THAT(std::vector<std::string>(lines.begin() + 1, lines.end()),
              ElementsAre("iptables -w -N SWARMBOX-RADIO-OUT",
                          "iptables -w -A SWARMBOX-RADIO-OUT -d 10.77.2.12/32 -m statistic --mode random --probability 0.1 "
                          "-j TEE --gateway 10.77.2.12",
                          "iptables -w -A SWARMBOX-RADIO-OUT -d 10.77.2.11/32 -m statistic --mode random --probability 0.1 "
                          "-j TEE --gateway 10.77.2.11",
                          "iptables -w -A SWARMBOX-RADIO-OUT -d 10.77.2.13/32 -m statistic --mode random --probability 0.1 "
                          "-j TEE --gateway 10.77.2.13",
                          "iptables -w -A SWARMBOX-RADIO-OUT -j NFQUEUE --queue-num 0 --queue-bypass",
                          "iptables -w -I OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT"));
  EXPECT_THAT(Lines(plan->undo),
              ElementsAre("iptables -w -D OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT", "iptables -w -F SWARMBOX-RADIO-OUT",
                          "iptables -w -X SWARMBOX-RADIO-OUT",
                          "/usr/bin/swarmbox-netemd stop --pidfile /run/swarmbox-netemd-0.pid"));
}

TEST(RadioPlan, UserspaceDuplicationAloneNeedsNoDaemon) {
  // Per destination, without delay: TEE then RETURN, no queue and no daemon.
  auto plan = PlanRadio(Rules("rules:\n  - {to: [scout_2], duplicate: 0.05}\n"), Link(), Mechanism::kUserspace);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_THAT(Lines(plan->apply),
              ElementsAre("iptables -w -N SWARMBOX-RADIO-OUT",
                          "iptables -w -A SWARMBOX-RADIO-OUT -d 10.77.2.11/32 -m statistic --mode random --probability 0.05 "
                          "-j TEE --gateway 10.77.2.11",
                          "iptables -w -A SWARMBOX-RADIO-OUT -d 10.77.2.11/32 -j RETURN",
                          "iptables -w -I OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT"));
  EXPECT_THAT(Lines(plan->undo),
              ElementsAre("iptables -w -D OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT", "iptables -w -F SWARMBOX-RADIO-OUT",
                          "iptables -w -X SWARMBOX-RADIO-OUT"));
}

TEST(RadioPlan, UserspacePerDestinationRulesComeBeforeTheAllTrafficRule) {
  RadioPlanOptions options;
  options.seed = 7;
  auto plan = PlanRadio(Rules("rules:\n"
                              "  - {delay_ms: 20, loss: 0.02}\n"
                              "  - {to: [scout_2], delay_ms: 300, rate_kbit: 64}\n"
                              "  - {to: [lifter], loss: 0.3}\n"),
                        Link(), Mechanism::kUserspace, options);
  ASSERT_TRUE(plan) << plan.error().ToString();
  std::vector<std::string> lines = Lines(plan->apply);
  ASSERT_EQ(lines.size(), 18u);
  EXPECT_THAT(std::vector<std::string>(lines.begin(), lines.begin() + 6),
              ElementsAre("tc qdisc replace dev eth1 root handle 1: htb default 1",
                          "tc class replace dev eth1 parent 1: classid 1:1 htb rate 10gbit",
                          "tc class replace dev eth1 parent 1: classid 1:10 htb rate 64kbit ceil 64kbit",
                          "tc filter add dev eth1 parent 1: protocol ip prio 1 u32 match ip dst 10.77.2.11/32 flowid 1:10",
                          "tc class replace dev eth1 parent 1: classid 1:11 htb rate 10gbit",
                          "tc filter add dev eth1 parent 1: protocol ip prio 1 u32 match ip dst 10.77.2.12/32 flowid 1:11"));
  EXPECT_THAT(lines[6], ::testing::StartsWith("/usr/bin/swarmbox-netemd run --queue 0 --delay-us 20000 "));
  EXPECT_THAT(lines[7], ::testing::StartsWith("/usr/bin/swarmbox-netemd run --queue 1 --delay-us 300000 "));
  EXPECT_THAT(std::vector<std::string>(lines.begin() + 8, lines.end()),
              ElementsAre("iptables -w -N SWARMBOX-RADIO-OUT",
                          "iptables -w -A SWARMBOX-RADIO-OUT -d 10.77.2.11/32 -j NFQUEUE --queue-num 1 --queue-bypass",
                          "iptables -w -A SWARMBOX-RADIO-OUT -d 10.77.2.12/32 -j RETURN",
                          "iptables -w -A SWARMBOX-RADIO-OUT -j NFQUEUE --queue-num 0 --queue-bypass",
                          "iptables -w -I OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT",
                          "iptables -w -N SWARMBOX-RADIO-IN",
                          "iptables -w -A SWARMBOX-RADIO-IN -s 10.77.2.11/32 -j RETURN",
                          "iptables -w -A SWARMBOX-RADIO-IN -s 10.77.2.12/32 -m statistic --mode random --probability 0.3 -j DROP",
                          "iptables -w -A SWARMBOX-RADIO-IN -m statistic --mode random --probability 0.02 -j DROP",
                          "iptables -w -I INPUT -i eth1 -j SWARMBOX-RADIO-IN"));
  EXPECT_THAT(Lines(plan->undo),
              ElementsAre("iptables -w -D INPUT -i eth1 -j SWARMBOX-RADIO-IN", "iptables -w -F SWARMBOX-RADIO-IN",
                          "iptables -w -X SWARMBOX-RADIO-IN", "iptables -w -D OUTPUT -o eth1 -j SWARMBOX-RADIO-OUT",
                          "iptables -w -F SWARMBOX-RADIO-OUT", "iptables -w -X SWARMBOX-RADIO-OUT",
                          "/usr/bin/swarmbox-netemd stop --pidfile /run/swarmbox-netemd-0.pid",
                          "/usr/bin/swarmbox-netemd stop --pidfile /run/swarmbox-netemd-1.pid",
                          "tc qdisc del dev eth1 root"));
}

TEST(RadioPlan, UserspaceDaemonSeedsAreDerivedFromTheTrialSeed) {
  RadioPlanOptions a;
  a.seed = 42;
  RadioPlanOptions b = a;
  b.seed = 43;
  const auto rules = Rules("{delay_ms: 5, jitter_ms: 1}");
  auto p1 = PlanRadio(rules, Link(), Mechanism::kUserspace, a);
  auto p2 = PlanRadio(rules, Link(), Mechanism::kUserspace, a);
  auto p3 = PlanRadio(rules, Link(), Mechanism::kUserspace, b);
  ASSERT_TRUE(p1 && p2 && p3);
  EXPECT_EQ(p1->apply[0].argv, p2->apply[0].argv);
  EXPECT_NE(p1->apply[0].argv, p3->apply[0].argv);
}

TEST(RadioPlan, UserspaceRefusesWhatOnlyNetemCanDoWithTheReason) {
  const auto rules = Rules("{delay_ms: 10, loss: 0.1, loss_correlation: 0.5}");
  auto plan = PlanRadio(rules, Link(), Mechanism::kUserspace);
  ASSERT_FALSE(plan);
  EXPECT_EQ(plan.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(plan.error().where(), "trial.yaml:1:1");
  EXPECT_EQ(plan.error().message(),
            "'loss_correlation' cannot be honoured on this host: the kernel has no sch_netem and the userspace "
            "mechanism draws each loss independently with iptables statistic");
  EXPECT_TRUE(PlanRadio(rules, Link(), Mechanism::kKernelNetem));
}

TEST(RadioPlan, RefusesAPeerWithoutAnAddress) {
  auto plan = PlanRadio(Rules("{to: [scout_9], loss: 0.1}"), Link(), Mechanism::kKernelNetem);
  ASSERT_FALSE(plan);
  EXPECT_EQ(plan.error().message(), "no mesh address known for peer 'scout_9' of scout_1");
}

TEST(RadioPlan, NoRulesIsAnEmptyPlan) {
  auto plan = PlanRadio({}, Link(), Mechanism::kUserspace);
  ASSERT_TRUE(plan);
  EXPECT_TRUE(plan->apply.empty());
  EXPECT_TRUE(plan->undo.empty());
}

TEST(RadioPlan, ChangeUndoesTheOldThenAppliesTheNew) {
  const auto base = Rules("{loss: 0.05}");
  const auto fault = Rules("{delay_ms: 100}");
  auto change = PlanRadioChange(base, fault, Link(), Mechanism::kKernelNetem);
  ASSERT_TRUE(change) << change.error().ToString();
  EXPECT_THAT(Lines(change->apply), ElementsAre("tc qdisc del dev eth1 root",
                                                "tc qdisc replace dev eth1 root netem limit 19532 delay 100ms"));
  EXPECT_THAT(Lines(change->undo), ElementsAre("tc qdisc del dev eth1 root"));
}

TEST(RadioPlan, ComposeAllTrafficOverlayReplacesTheBase) {
  const auto base = Rules("rules: [{loss: 0.05}, {to: [lifter], delay_ms: 5}]");
  const auto overlay = Rules("{delay_ms: 100}");
  EXPECT_EQ(ComposeRadio(base, overlay), overlay);
  EXPECT_EQ(ComposeRadio(base, {}), base);
  EXPECT_EQ(ComposeRadio({}, overlay), overlay);
}

TEST(RadioPlan, ComposePerDestinationOverlayTakesItsPeersFromTheBase) {
  const auto base = Rules("rules: [{loss: 0.05}, {to: [lifter, scout_2], delay_ms: 5}]");
  const auto overlay = Rules("{to: [scout_2], loss: 0.5}");
  const auto composed = ComposeRadio(base, overlay);
  ASSERT_EQ(composed.size(), 3u);
  EXPECT_TRUE(composed[0].to.empty());
  EXPECT_EQ(composed[1].to, std::vector<std::string>{"lifter"});
  EXPECT_EQ(composed[2], overlay[0]);
}

}  // namespace
}  // namespace swarmbox::faults
