// End to end: the userspace radio plan (swarmbox-netemd on NFQUEUE, iptables statistic) on a real
// veth pair between two network namespaces this test creates and always deletes. Needs root and
// the kernel's nfnetlink_queue; without them the test FAILS with the reason (it never skips).
//
// One-way delay is measured with udp_probe.hpp (the same probe measures kernel netem in the
// user-mode Linux guest, tests/orchestrator/netem_guest): both UDP sockets live in this process
// (each created inside its namespace), so send and arrival times come from one clock.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>

#include "swarmbox/faults/posix_command_runner.hpp"
#include "swarmbox/faults/partition_plan.hpp"
#include "swarmbox/faults/radio_plan.hpp"
#include "support/veth_pair.hpp"
#include "test_util.hpp"
#include "udp_probe.hpp"

namespace swarmbox::faults {
namespace {

using testing::MeasureOneWay;
using testing::ProbeOptions;
using Sample = testing::ProbeSample;
using testing::Yaml;

class NetnsPair : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(geteuid(), 0u) << "this e2e test creates network namespaces and needs root (CAP_SYS_ADMIN, "
                                "CAP_NET_ADMIN); run it as root";
    created_ = true;
    const Status made = pair_.Create({"sbf", "swarmbox-faults-e2e", kAddrA, kAddrB, false, SWARMBOX_NETEMD_PATH});
    ASSERT_TRUE(made) << made.error().ToString();
  }

  void TearDown() override {
    if (!created_) return;
    // Stop any daemon the test left (their pidfiles), then delete the namespaces (veth and
    // iptables rules go with them) and the scratch directory. Best effort, every path.
    pair_.Remove();
    auto left = runner_.Run({"ip", "netns", "list"});
    if (left) {
      EXPECT_EQ(left->stdout_text.find("sbf-" + std::to_string(getpid())), std::string::npos);
    }
  }

  void Must(const std::vector<std::string>& argv) {
    auto out = runner_.Run(argv);
    ASSERT_TRUE(out) << out.error().ToString();
    ASSERT_EQ(out->exit_code, 0) << "`" << CommandText(argv) << "` failed: " << out->stderr_text;
  }

  LinkTarget Link(const std::string& node, const std::string& iface, const std::string& peer,
                  const std::string& peer_ip) {
    return LinkTarget{node, iface, {{peer, peer_ip}}, kAssumedLinkRateKbit};
  }

  RadioPlanOptions Options(const char* side) {
    RadioPlanOptions o;
    o.seed = 42;
    o.netemd = SWARMBOX_NETEMD_PATH;
    o.pid_dir = (dir_ / side).string();
    return o;
  }

  // Sends `count` datagrams A -> B every `spacing_us`, returns what B received and when.
  Sample Measure(int count, std::int64_t spacing_us, const char* to_addr = kAddrB) {
    ProbeOptions o;
    o.from_netns = ns_a_;
    o.to_netns = ns_b_;
    o.to_addr = to_addr;
    o.port = kPort;
    o.count = count;
    o.spacing_us = spacing_us;
    auto sample = MeasureOneWay(o);
    if (!sample) {
      ADD_FAILURE() << sample.error().ToString();
      return Sample{};
    }
    return *sample;
  }

  // user + system CPU of the daemon whose pidfile is side/swarmbox-netemd-0.pid [s].
  double DaemonCpuSeconds(const char* side) {
    std::ifstream pidfile(dir_ / side / "swarmbox-netemd-0.pid");
    long pid = 0;
    pidfile >> pid;
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string line;
    std::getline(stat, line);
    std::istringstream fields(line.substr(line.rfind(')') + 2));
    std::vector<std::string> f{std::istream_iterator<std::string>(fields), std::istream_iterator<std::string>()};
    EXPECT_GT(f.size(), 13u) << "no /proc/" << pid << "/stat";
    if (f.size() <= 13) return 0.0;
    // Fields 14 and 15 of /proc/pid/stat (utime, stime) are f[11], f[12] after the ')'.
    return static_cast<double>(std::stoll(f[11]) + std::stoll(f[12])) / static_cast<double>(sysconf(_SC_CLK_TCK));
  }

  // Packets namespace `ns`'s stack refused as malformed (Ip InHdrErrors + Udp InErrors).
  std::int64_t ReceiveErrors(const std::string& ns) {
    auto errors = testing::ReceiveErrors(runner_, ns);
    EXPECT_TRUE(errors) << errors.error().ToString();
    return errors ? *errors : -1;
  }

  std::string IptablesRules(const std::string& ns) {
    auto out = runner_.Run({"ip", "netns", "exec", ns, "iptables", "-w", "-S"});
    return out ? out->stdout_text : out.error().ToString();
  }

  static constexpr const char* kAddrA = "10.213.7.1";
  static constexpr const char* kAddrB = "10.213.7.2";
  static constexpr const char* kAddrC = "10.213.7.3";
  static constexpr std::uint16_t kPort = 47001;

  PosixCommandRunner runner_;
  swarmbox::testing::VethPair pair_{runner_};
  const std::string& ns_a_ = pair_.ns_a;
  const std::string& ns_b_ = pair_.ns_b;
  const std::string& if_a_ = pair_.if_a;
  const std::string& if_b_ = pair_.if_b;
  const std::filesystem::path& dir_ = pair_.dir;
  bool created_ = false;
};

TEST_F(NetnsPair, UserspacePlanDelaysJittersAndDropsAsSpecified) {
  // The mesh-wide block applied to both agents, as the runner does for network.mesh.
  auto rules = ParseRadioRules(Yaml("{delay_ms: 50, jitter_ms: 10, distribution: normal, loss: 0.05}"), "radio");
  ASSERT_TRUE(rules) << rules.error().ToString();
  auto plan_a = PlanRadio(*rules, Link("a", if_a_, "b", kAddrB), Mechanism::kUserspace, Options("a"));
  auto plan_b = PlanRadio(*rules, Link("b", if_b_, "a", kAddrA), Mechanism::kUserspace, Options("b"));
  ASSERT_TRUE(plan_a && plan_b);
  PrefixCommandRunner in_a(runner_, {"ip", "netns", "exec", ns_a_});
  PrefixCommandRunner in_b(runner_, {"ip", "netns", "exec", ns_b_});
  Status applied_a = RunCommands(in_a, plan_a->apply);
  ASSERT_TRUE(applied_a) << applied_a.error().ToString();
  Status applied_b = RunCommands(in_b, plan_b->apply);
  ASSERT_TRUE(applied_b) << applied_b.error().ToString();
  EXPECT_NE(IptablesRules(ns_a_).find("-A SWARMBOX-RADIO-OUT -j NFQUEUE --queue-num 0 --queue-bypass"), std::string::npos);

  const Sample s = Measure(3000, 1000);  // 3,000 datagrams, 1 ms apart
  ASSERT_EQ(s.sent, 3000u);
  ASSERT_GT(s.received(), 2500u);
  const double loss = 1.0 - static_cast<double>(s.received()) / s.sent;
  std::printf("userspace plan, 50+-10 ms normal, loss 5%%: sent %u received %u loss %.2f%% mean %.2f ms "
              "sd %.2f ms p50 %.2f ms p99 %.2f ms\n",
              s.sent, s.received(), 100 * loss, s.Mean(), s.StdDev(), s.Quantile(0.5), s.Quantile(0.99));
  RecordProperty("mean_delay_ms", std::to_string(s.Mean()));
  RecordProperty("sd_delay_ms", std::to_string(s.StdDev()));
  RecordProperty("loss", std::to_string(loss));
  // Loss: binomial with p = 0.05 over 3,000 packets, sd = sqrt(0.05 x 0.95 / 3000) = 0.40%;
  // allow 4 sd (1.6%).
  EXPECT_NEAR(loss, 0.05, 0.016);
  // Delay: the standard error of the mean of N(50, 10) over ~2,850 packets is 0.19 ms; allow
  // 5 of them below (0.95 ms) and, above, 5 of them plus 3 ms for the daemon's and this shared
  // machine's scheduling latency.
  EXPECT_GT(s.Mean(), 50.0 - 0.95);
  EXPECT_LT(s.Mean(), 50.0 + 0.95 + 3.0);
  // Spread: sigma from the interquartile range (1.349 sigma for a normal): a few datagrams the
  // shared machine held up by tens of ms move the sample sd (CI on 2026-11-28: sd 13.1 ms, p99
  // 104 ms) but not the quartiles. Its relative standard error over ~2,850 values is ~2.1%;
  // allow 15% for the same scheduling noise.
  const double sigma_iqr = (s.Quantile(0.75) - s.Quantile(0.25)) / 1.349;
  RecordProperty("sigma_from_iqr_ms", std::to_string(sigma_iqr));
  EXPECT_NEAR(sigma_iqr, 10.0, 1.5) << "sd " << s.StdDev();

  // Undo: chains, hooks and daemons gone, traffic back to a bare veth.
  Status undone_a = RunAllCommands(in_a, plan_a->undo);
  EXPECT_TRUE(undone_a) << undone_a.error().ToString();
  Status undone_b = RunAllCommands(in_b, plan_b->undo);
  EXPECT_TRUE(undone_b) << undone_b.error().ToString();
  EXPECT_EQ(IptablesRules(ns_a_).find("SWARMBOX"), std::string::npos) << IptablesRules(ns_a_);
  EXPECT_EQ(IptablesRules(ns_b_).find("SWARMBOX"), std::string::npos) << IptablesRules(ns_b_);
  EXPECT_TRUE(std::filesystem::is_empty(dir_ / "a"));
  const Sample after = Measure(300, 1000);
  EXPECT_EQ(after.received(), after.sent);
  EXPECT_LT(after.Mean(), 5.0);
}

TEST_F(NetnsPair, GilbertElliottLossComesInBurstsAndTheSenderSeesNoError) {
  // netem "loss gemodel 2% 25% 100% 0%": bad spells of 4 packets on average, all lost; 7.4 % in the
  // long run. Drawn and dropped by the daemon on egress (NF_DROP after the packet was queued).
  auto rules = ParseRadioRules(Yaml("{delay_ms: 5, gilbert_elliott: {p: 0.02, r: 0.25, loss_bad: 1.0, loss_good: 0.0}}"),
                               "radio");
  ASSERT_TRUE(rules) << rules.error().ToString();
  auto plan = PlanRadio(*rules, Link("a", if_a_, "b", kAddrB), Mechanism::kUserspace, Options("a"));
  ASSERT_TRUE(plan) << plan.error().ToString();
  PrefixCommandRunner in_a(runner_, {"ip", "netns", "exec", ns_a_});
  Status applied = RunCommands(in_a, plan->apply);
  ASSERT_TRUE(applied) << applied.error().ToString();
  const Sample s = Measure(3000, 1000);
  ASSERT_EQ(s.sent, 3000u);  // every sendto() succeeded: the drop happens after the queue took it
  const double loss = 1.0 - static_cast<double>(s.received()) / s.sent;
  // Runs of consecutive lost numbers (the receiver keeps each packet's number).
  int bursts = 0;
  std::uint32_t expected = 0;
  for (std::uint32_t seq : s.seqs) {
    if (seq != expected) ++bursts;
    expected = seq + 1;
  }
  if (expected != s.sent) ++bursts;
  const double mean_burst = bursts > 0 ? static_cast<double>(s.sent - s.received()) / bursts : 0.0;
  std::printf("userspace Gilbert-Elliott p 2%% r 25%% loss_bad 100%%: sent %u received %u loss %.2f%% "
              "(stationary 7.41%%), %d bursts, mean burst %.2f packets (model 4)\n",
              s.sent, s.received(), 100 * loss, bursts, mean_burst);
  RecordProperty("ge_loss", std::to_string(loss));
  RecordProperty("ge_mean_burst", std::to_string(mean_burst));
  // The state is a Markov chain: over 3,000 packets the loss estimate's sd is
  // sqrt(pi (1 - pi) (2 - p - r) / ((p + r) n)) = 1.2 %; 4 sd either side.
  EXPECT_NEAR(loss, 0.0741, 0.048);
  // Geometric bursts of mean 4 over ~55 bursts: sd of the mean about 0.47; independent 7.4 % loss
  // would give 1.08. Allow 4.0 +- 2.
  EXPECT_NEAR(mean_burst, 4.0, 2.0);
  EXPECT_TRUE(RunAllCommands(in_a, plan->undo));
}

TEST_F(NetnsPair, CorruptionFlipsABitThatTheReceiversChecksumsCatch) {
  // netem "corrupt 10%": the daemon flips one random bit of 10 % of the packets on egress and gives
  // them back with the new bytes; checksums are left alone, so B's stack drops each one (IP header
  // checksum, version or length check for a bit in the IP header, UDP checksum or length check for
  // one in the UDP header or payload: every bit is covered) and the sender sees no error.
  auto rules = ParseRadioRules(Yaml("{corrupt: 0.1}"), "radio");
  ASSERT_TRUE(rules) << rules.error().ToString();
  auto plan = PlanRadio(*rules, Link("a", if_a_, "b", kAddrB), Mechanism::kUserspace, Options("a"));
  ASSERT_TRUE(plan) << plan.error().ToString();
  PrefixCommandRunner in_a(runner_, {"ip", "netns", "exec", ns_a_});
  Status applied = RunCommands(in_a, plan->apply);
  ASSERT_TRUE(applied) << applied.error().ToString();
  const std::int64_t receive_errors_before = ReceiveErrors(ns_b_);
  const Sample s = Measure(3000, 1000);
  const std::int64_t receive_errors = ReceiveErrors(ns_b_) - receive_errors_before;
  ASSERT_EQ(s.sent, 3000u);  // every sendto() succeeded
  const double delivered = static_cast<double>(s.received()) / s.sent;
  std::printf("userspace corrupt 10%%: sent %u received %u (%.2f%%), receiver's stack refused %lld\n", s.sent,
              s.received(), 100 * delivered, static_cast<long long>(receive_errors));
  RecordProperty("corrupt_delivered", std::to_string(delivered));
  // Binomial with p = 0.1 over 3,000 packets: sd = sqrt(0.1 x 0.9 / 3000) = 0.55 %; allow 4 sd.
  EXPECT_NEAR(delivered, 0.9, 0.022);
  // Where the missing datagrams went. A bit of the destination address (32 of the 352 bits of these
  // 44-byte packets) makes A's stack re-route the packet after the verdict (netfilter does after a
  // LOCAL_OUT change), to an address nobody answers: lost at A. Every other flip reaches B, whose
  // stack refuses it as malformed. So B's error counters should hold 320/352 = 90.9 % of the missing
  // ones: binomial over ~300 corrupted packets, sd 1.7 %; allow 4 sd.
  const double missing = static_cast<double>(s.sent - s.received());
  ASSERT_GT(missing, 0.0);
  std::printf("  of the %.0f missing: %.1f%% refused by B's stack (IP header / UDP errors), model 90.9%%\n", missing,
              100 * static_cast<double>(receive_errors) / missing);
  EXPECT_NEAR(static_cast<double>(receive_errors) / missing, 320.0 / 352.0, 0.066);
  EXPECT_TRUE(RunAllCommands(in_a, plan->undo));
  const Sample after = Measure(300, 1000);
  EXPECT_EQ(after.received(), after.sent);
}

TEST_F(NetnsPair, DuplicationSendsASecondCopyAndTheSenderSeesNoError) {
  // netem "duplicate 10%" (with 5 ms delay): iptables TEE clones 10 % of A's datagrams to B; each
  // clone goes back through the daemon's queue for its own delay and is not cloned again.
  auto rules = ParseRadioRules(Yaml("{delay_ms: 5, duplicate: 0.1}"), "radio");
  ASSERT_TRUE(rules) << rules.error().ToString();
  auto plan = PlanRadio(*rules, Link("a", if_a_, "b", kAddrB), Mechanism::kUserspace, Options("a"));
  ASSERT_TRUE(plan) << plan.error().ToString();
  PrefixCommandRunner in_a(runner_, {"ip", "netns", "exec", ns_a_});
  Status applied = RunCommands(in_a, plan->apply);
  ASSERT_TRUE(applied) << applied.error().ToString();
  const Sample s = Measure(3000, 1000);
  ASSERT_EQ(s.sent, 3000u);  // every sendto() succeeded
  const double ratio = static_cast<double>(s.datagrams) / s.sent;
  // Packets the NFQUEUE rule sent to the daemon: the originals and the clones.
  auto listing = runner_.Run({"ip", "netns", "exec", ns_a_, "iptables", "-w", "-L", "SWARMBOX-RADIO-OUT", "-v", "-x", "-n"});
  ASSERT_TRUE(listing) << listing.error().ToString();
  long long queued = -1;
  std::istringstream rows(listing->stdout_text);
  for (std::string row; std::getline(rows, row);) {
    if (row.find("NFQUEUE") != std::string::npos) queued = std::stoll(row);
  }
  std::printf("userspace duplicate 10%% (delay 5 ms): sent %u, B received %u datagrams (%.2f%%) of %u distinct "
              "numbers; %lld went through the daemon's queue\n",
              s.sent, s.datagrams, 100 * ratio, s.received(), queued);
  // Every clone went through the queue too (its own delay), none was cloned again.
  EXPECT_EQ(queued, static_cast<long long>(s.datagrams));
  RecordProperty("duplicate_ratio", std::to_string(ratio));
  EXPECT_EQ(s.received(), s.sent);  // nothing lost
  // Binomial with p = 0.1 over 3,000 packets: sd of the extra fraction 0.55 %; allow 4 sd.
  EXPECT_NEAR(ratio, 1.1, 0.022);
  EXPECT_TRUE(RunAllCommands(in_a, plan->undo));
  EXPECT_EQ(IptablesRules(ns_a_).find("SWARMBOX"), std::string::npos) << IptablesRules(ns_a_);
  const Sample after = Measure(300, 1000);
  EXPECT_EQ(after.datagrams, after.sent);
}

TEST_F(NetnsPair, FixedDelayHasATightSpread) {
  auto rules = ParseRadioRules(Yaml("{delay_ms: 50}"), "radio");
  ASSERT_TRUE(rules);
  auto plan = PlanRadio(*rules, Link("a", if_a_, "b", kAddrB), Mechanism::kUserspace, Options("a"));
  ASSERT_TRUE(plan);
  PrefixCommandRunner in_a(runner_, {"ip", "netns", "exec", ns_a_});
  Status applied = RunCommands(in_a, plan->apply);
  ASSERT_TRUE(applied) << applied.error().ToString();
  const double cpu_before_s = DaemonCpuSeconds("a");
  const Sample s = Measure(1000, 2000);
  const double cpu_per_packet_us = (DaemonCpuSeconds("a") - cpu_before_s) * 1e6 / s.sent;
  std::printf("swarmbox-netemd CPU: %.1f us per packet (user + system, 1,000 packets)\n", cpu_per_packet_us);
  RecordProperty("daemon_cpu_us_per_packet", std::to_string(cpu_per_packet_us));
  ASSERT_EQ(s.received(), s.sent);  // no loss was asked for
  std::printf("userspace plan, fixed 50 ms: mean %.3f ms p50 %.3f ms p99 %.3f ms max %.3f ms\n", s.Mean(),
              s.Quantile(0.5), s.Quantile(0.99), s.Quantile(1.0));
  // Never early; late by the daemon's wake-up latency only. On an idle machine that is +50.2 ms,
  // p99 +51 ms (issue facts). This 2-core machine runs at a load of ~15 (seven other builds): we
  // measured a median of +0.1..0.2 ms (once +1.6 ms) and a p99 of +4..25 ms there. The median is
  // the precision claim (+2.5 ms allowed); the tail only shows CPU starvation (+40 ms allowed).
  EXPECT_GE(s.Quantile(0.0), 50.0);
  EXPECT_LT(s.Quantile(0.5), 52.5);
  EXPECT_LT(s.Quantile(0.99), 90.0);
  EXPECT_TRUE(RunAllCommands(in_a, plan->undo));
}

TEST_F(NetnsPair, TrafficFlowsWhenTheDaemonDies) {
  // --queue-bypass: with no daemon bound to the queue the kernel accepts the packets.
  auto rules = ParseRadioRules(Yaml("{delay_ms: 200}"), "radio");
  ASSERT_TRUE(rules);
  auto plan = PlanRadio(*rules, Link("a", if_a_, "b", kAddrB), Mechanism::kUserspace, Options("a"));
  ASSERT_TRUE(plan);
  PrefixCommandRunner in_a(runner_, {"ip", "netns", "exec", ns_a_});
  Status applied = RunCommands(in_a, plan->apply);
  ASSERT_TRUE(applied) << applied.error().ToString();
  Must({SWARMBOX_NETEMD_PATH, "stop", "--pidfile", (dir_ / "a" / "swarmbox-netemd-0.pid").string()});
  EXPECT_NE(IptablesRules(ns_a_).find("NFQUEUE"), std::string::npos);  // the rule is still there
  const Sample s = Measure(200, 2000);
  EXPECT_EQ(s.received(), s.sent);
  EXPECT_LT(s.Mean(), 5.0);
}

TEST_F(NetnsPair, PerDestinationRuleImpairsOnlyThatPeer) {
  // A second address on B's side plays a second peer: the rule for "c" must leave "b" alone.
  Must({"ip", "-n", ns_b_, "addr", "add", std::string(kAddrC) + "/24", "dev", if_b_});
  auto rules = ParseRadioRules(Yaml("{to: [c], delay_ms: 80, rate_kbit: 2000}"), "radio");
  ASSERT_TRUE(rules) << rules.error().ToString();
  LinkTarget link{"a", if_a_, {{"b", kAddrB}, {"c", kAddrC}}, kAssumedLinkRateKbit};
  auto plan = PlanRadio(*rules, link, Mechanism::kUserspace, Options("a"));
  ASSERT_TRUE(plan) << plan.error().ToString();
  PrefixCommandRunner in_a(runner_, {"ip", "netns", "exec", ns_a_});
  Status applied = RunCommands(in_a, plan->apply);  // htb + u32 filter for the rate, NFQUEUE -d c
  ASSERT_TRUE(applied) << applied.error().ToString();
  const Sample to_b = Measure(300, 2000);
  const Sample to_c = Measure(300, 2000, kAddrC);
  std::printf("per-destination 80 ms to c only: to b mean %.3f ms, to c mean %.3f ms p50 %.3f ms\n", to_b.Mean(),
              to_c.Mean(), to_c.Quantile(0.5));
  EXPECT_EQ(to_b.received(), to_b.sent);
  EXPECT_EQ(to_c.received(), to_c.sent);
  EXPECT_LT(to_b.Mean(), 5.0);
  EXPECT_GE(to_c.Quantile(0.0), 80.0);
  EXPECT_LT(to_c.Quantile(0.5), 82.5);  // the same wake-up allowance as FixedDelayHasATightSpread
  Status undone = RunAllCommands(in_a, plan->undo);
  EXPECT_TRUE(undone) << undone.error().ToString();
  auto qdisc = runner_.Run({"ip", "netns", "exec", ns_a_, "tc", "qdisc", "show", "dev", if_a_});
  ASSERT_TRUE(qdisc);
  EXPECT_EQ(qdisc->stdout_text.find("htb"), std::string::npos) << qdisc->stdout_text;
}

TEST_F(NetnsPair, KernelNetemArgvPassesTcsOwnParser) {
  // tc parses every netem option (and reads the distribution tables) before it asks the kernel, so
  // on a kernel without sch_netem a well-formed command fails only with "Specified qdisc kind is
  // unknown" and a malformed one with a parse error. Where the kernel has netem, it must apply.
  const char* specs[] = {
      "{delay_ms: 100, jitter_ms: 20, distribution: normal, correlation: 0.25, loss: 0.05, loss_correlation: 0.1,"
      " duplicate: 0.01, corrupt: 0.001, reorder: 0.2, reorder_correlation: 0.5, reorder_gap: 5, rate_kbit: 2000}",
      "{delay_ms: 12.5, jitter_ms: 0.5, distribution: pareto}",
      "{delay_ms: 40, jitter_ms: 10, distribution: paretonormal}",
      "{gilbert_elliott: {p: 0.05, r: 0.5, loss_bad: 0.9, loss_good: 0.01}}",
      "{rules: [{loss: 0.01}, {to: [b], delay_ms: 300, rate_kbit: 64}]}",
  };
  PrefixCommandRunner in_a(runner_, {"ip", "netns", "exec", ns_a_});
  for (const char* spec : specs) {
    auto rules = ParseRadioRules(Yaml(spec), "radio");
    ASSERT_TRUE(rules) << rules.error().ToString();
    auto plan = PlanRadio(*rules, Link("a", if_a_, "b", kAddrB), Mechanism::kKernelNetem);
    ASSERT_TRUE(plan) << plan.error().ToString();
    for (const Command& c : plan->apply) {
      auto out = in_a.Run(c.argv);
      ASSERT_TRUE(out) << out.error().ToString();
      const bool netem_step = std::find(c.argv.begin(), c.argv.end(), "netem") != c.argv.end();
      if (out->exit_code != 0) {
        EXPECT_TRUE(netem_step) << CommandText(c.argv) << ": " << out->stderr_text;
        EXPECT_NE(out->stderr_text.find(kNoNetemMessage), std::string::npos)
            << CommandText(c.argv) << ": " << out->stderr_text;
      }
    }
    (void)RunAllCommands(in_a, plan->undo);
  }
}

TEST_F(NetnsPair, PartitionCutsOneWayAndHeals) {
  // One-way from a: b drops what comes from a; a still hears b.
  const std::vector<MeshNode> nodes = {{"a", if_a_, kAddrA}, {"b", if_b_, kAddrB}};
  auto plan = PlanPartition(PartitionFault{{{"a"}, {"b"}}, true}, nodes, 3);
  ASSERT_TRUE(plan) << plan.error().ToString();
  ASSERT_EQ(plan->apply.count("a"), 0u);
  PrefixCommandRunner in_b(runner_, {"ip", "netns", "exec", ns_b_});
  Status applied = RunCommands(in_b, plan->apply.at("b"));
  ASSERT_TRUE(applied) << applied.error().ToString();
  const Sample cut = Measure(100, 1000);
  EXPECT_EQ(cut.sent, 100u);  // the sender sees no error (the drop is on b's ingress)
  EXPECT_EQ(cut.received(), 0u);
  Status healed = RunAllCommands(in_b, plan->undo.at("b"));
  ASSERT_TRUE(healed) << healed.error().ToString();
  EXPECT_EQ(IptablesRules(ns_b_).find("SWARMBOX"), std::string::npos);
  const Sample after = Measure(100, 1000);
  EXPECT_EQ(after.received(), after.sent);
}

TEST_F(NetnsPair, DaemonReportsABusyQueue) {
  auto first = runner_.Run({"ip", "netns", "exec", ns_a_, SWARMBOX_NETEMD_PATH, "run", "--queue", "3", "--pidfile",
                            (dir_ / "a" / "q3.pid").string(), "--daemonize"});
  ASSERT_TRUE(first);
  ASSERT_EQ(first->exit_code, 0) << first->stderr_text;
  auto second = runner_.Run({"ip", "netns", "exec", ns_a_, SWARMBOX_NETEMD_PATH, "run", "--queue", "3", "--daemonize"});
  ASSERT_TRUE(second);
  EXPECT_EQ(second->exit_code, 1);
  EXPECT_NE(second->stderr_text.find("nfq_create_queue 3"), std::string::npos) << second->stderr_text;
}

}  // namespace
}  // namespace swarmbox::faults
