// End to end: the kernel netem path (the fault code's own tc argv) on a kernel that has
// sch_netem. This machine's kernel has none, so each test boots Debian's user-mode Linux
// (user-mode-linux, installed by scripts/setup.sh) with swarmbox-netem-guest as its init; the guest
// runs one scenario (guest_scenarios.hpp) on two network namespaces joined by a veth pair, measures
// with the userspace e2e test's probe (tests/orchestrator/faults/udp_probe.hpp) and prints its
// figures on the console; these tests judge them with the tolerances netemd_e2e_test.cpp applies to
// the userspace mechanism, so both mechanisms are held to the same numbers. Without linux.uml or
// its module tree the tests FAIL with the reason. They skip, with the reason, on one host only:
// one where Debian 12's UML cannot run any process at all (UmlUserspaceProblem below).
//
// Timing inside the guest: UML's clock is the host's CLOCK_MONOTONIC and netem's timers are the
// host's timers delivered to the UML process, so the guest is late exactly when the host does not
// schedule that process: the same kind of lateness the userspace daemon sees, which is what the
// userspace tolerances were set for (BENCHMARKS.md has both sets of figures).
#include <cpuid.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "guest_console.hpp"
#include "guest_measurements.hpp"
#include "support/files.hpp"
#include "swarmbox/images/find_program.hpp"
#include "uml_guest.hpp"

namespace swarmbox::netem_guest {
namespace {

// Why Debian 12's user-mode Linux cannot run a process on this host, or "" when it can. UML 6.1
// keeps a process's FP state in an 832-byte XSAVE buffer (x87, SSE, AVX: struct _xstate) and
// restores it with PTRACE_SETREGSET; the host kernel takes only a buffer of its own XSAVE size,
// which AVX-512 and AMX make larger (11,008 bytes on the machine of 2026-11-28), and refuses any
// other with EFAULT: the guest's first process dies on its first FP restore (UML prints
// "userspace - ptrace set fp regs failed, errno = 14"; init is killed by SIGSEGV, exitcode 0xb).
// Probed, not assumed: /bin/true as the guest's init must exit (exitcode 0); once per process.
std::string UmlUserspaceProblem(const std::string& kernel) {
  static const std::string problem = [&kernel]() -> std::string {
    GuestBoot boot;
    boot.kernel = kernel;
    boot.init = "/bin/true";
    boot.scratch_dir = testing::MakeTempDir("swarmbox-netem-guest-probe-");
    Result<GuestRun> run = BootGuest(boot, std::chrono::seconds(60));
    std::error_code ec;
    std::filesystem::remove_all(boot.scratch_dir, ec);
    if (!run || run->console.find("exitcode=0x0000000b") == std::string::npos) return "";
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
    __get_cpuid_count(0xd, 0, &eax, &ebx, &ecx, &edx);
    return "Debian 12's user-mode Linux cannot run a process on this host: /bin/true as its init was killed "
           "by SIGSEGV (exitcode 0xb). UML 6.1 restores a process's FP state from an 832-byte XSAVE buffer "
           "and this host kernel takes only its own XSAVE size, " + std::to_string(ebx) +
           " bytes here (AVX-512/AMX), refusing others with EFAULT. The kernel netem path cannot be measured "
           "on this machine (a later UML, which sizes the buffer from the host, or a QEMU guest would).";
  }();
  return problem;
}

class NetemGuest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto kernel = images::FindProgram("linux.uml", "", {}, "");
    if (!kernel) return;  // BootOnce fails with the install command
    const std::string problem = UmlUserspaceProblem(*kernel);
    if (!problem.empty()) GTEST_SKIP() << problem;
  }
  void TearDown() override {
    if (dir_.empty()) return;
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
    dir_.clear();
  }

  // Boots the guest with `scenario` and reads its console; fatal failures say why it could not.
  //
  // A sample taken while the host did not run the guest at all is not a sample of netem's timing:
  // on this 2-core machine at a load of 10-15 the guest was seen unscheduled for up to 1.4 s (its
  // sender's lateness shows it), which by itself moves the 3,000-datagram mean by ~5 ms. For the
  // scenarios judged on delays (`timing`), an attempt whose probes saw the guest stopped for more
  // than kStarvedMs is therefore void and the guest is booted again, up to kAttempts times; the
  // tolerances apply unchanged to the attempt that counts, and if every attempt was starved the
  // test fails saying so. Counts (loss, duplicates, corruption, bursts, a partition) are not moved
  // by a stall (the probe's 4 MB socket buffer holds the burst after one): no retry there.
  void Boot(const std::string& scenario, bool timing) {
    constexpr double kStarvedMs = 250.0;  // where a stall alone eats the mean's 3 ms allowance
    constexpr int kAttempts = 3;
    std::string starved;
    for (int attempt = 1; attempt <= kAttempts; ++attempt) {
      ASSERT_NO_FATAL_FAILURE(BootOnce(scenario));
      const auto [stall_ms, probe] = console_.LongestStall();
      if (!timing || stall_ms <= kStarvedMs) return;
      char line[200];
      std::snprintf(line, sizeof line, "attempt %d: the guest went unscheduled for %.0f ms during probe %s\n",
                    attempt, stall_ms, probe.c_str());
      starved += line;
      std::printf("guest: %s", line);
    }
    FAIL() << "the host starved the guest (> " << kStarvedMs << " ms without running it) in all " << kAttempts
           << " attempts; no valid sample of netem:\n"
           << starved;
  }

  void BootOnce(const std::string& scenario) {
    auto kernel = images::FindProgram(
        "linux.uml", "", {}, "install Debian's user-mode-linux package (bash scripts/setup.sh does)");
    ASSERT_TRUE(kernel) << kernel.error().ToString();
    ASSERT_TRUE(std::filesystem::is_directory(kUmlModulesDir))
        << kUmlModulesDir
        << " is missing: the UML kernel's modules (sch_netem among them) come with user-mode-linux";
    TearDown();
    dir_ = testing::MakeTempDir("swarmbox-netem-guest-");
    ASSERT_FALSE(dir_.empty());
    GuestBoot boot;
    boot.kernel = *kernel;
    boot.init = SWARMBOX_NETEM_GUEST_BIN;
    boot.scratch_dir = dir_;
    boot.scenarios = {scenario};
    auto run = BootGuest(boot, std::chrono::seconds(240));
    ASSERT_TRUE(run) << run.error().ToString();
    raw_ = run->console;
    console_ = ParseGuestConsole(raw_);
    scenario_ = scenario;
    ASSERT_TRUE(console_.done()) << "the guest did not finish (exit " << run->exit_code << "); its console:\n"
                                 << raw_;
    ASSERT_EQ(console_.Errors(), "") << "its console:\n" << raw_;
    ASSERT_EQ(run->exit_code, 0) << raw_;
    std::printf("guest: scenario %s booted, ran and powered off in %.1f s\n", scenario.c_str(), run->wall_s);
  }

  // The `probe` record of this scenario; nullptr (and a failure) when the guest did not report it.
  const GuestRecord* Probe(const std::string& probe) {
    const GuestRecord* r = console_.Find(kEventMeasured, {{"scenario", scenario_}, {"probe", probe}});
    EXPECT_NE(r, nullptr) << "no probe " << probe << " in the console:\n" << raw_;
    return r;
  }

  // The probe's figure `key` as a number (NaN, and a failure, when absent).
  static double Num(const GuestRecord& r, const std::string& key) {
    const std::string v = r.Field(key);
    EXPECT_FALSE(v.empty()) << "no " << key << " in probe " << r.Field("probe");
    return v.empty() ? std::nan("") : std::stod(v);
  }

  // The normalized tc listing of node a's veth at `stage`.
  std::string Tree(const std::string& stage, const std::string& node = "a") {
    const GuestRecord* r =
        console_.Find(kEventTree, {{"scenario", scenario_}, {"drone", node}, {"stage", stage}});
    EXPECT_NE(r, nullptr) << "no " << stage << " listing in the console:\n" << raw_;
    return r == nullptr ? "<missing " + stage + ">" : NormalizeTcListing(r->Field("text"));
  }

  static void Print(const char* what, const GuestRecord& r) {
    std::printf(
        "kernel netem (guest), %s: sent %s received %s (%s datagrams) loss %.2f%% mean %s ms sd %s ms p50 %s "
        "ms "
        "p99 %s ms min %s max %s; sender at most %s ms late\n",
        what, r.Field("sent").c_str(), r.Field("received").c_str(), r.Field("datagrams").c_str(),
        100 * Num(r, "loss"), r.Field("mean_ms").c_str(), r.Field("sd_ms").c_str(), r.Field("p50_ms").c_str(),
        r.Field("p99_ms").c_str(), r.Field("min_ms").c_str(), r.Field("max_ms").c_str(),
        r.Field("send_late_max_ms").c_str());
  }

  // For timing failures: how long the guest went unscheduled during the probe (the host's load).
  static std::string Late(const GuestRecord& r) {
    return "(probe " + r.Field("probe") + ": the sender was at most " + r.Field("send_late_max_ms") +
           " ms late, i.e. the guest went unscheduled that long)";
  }

  // netem's rate spaces the frames by their length at the rate, on a schedule fixed at enqueue, so
  // the fitted rate can never come out above it (2 % for the fit). The guest is one process on a
  // host that CI loads with a second test: when it goes short of CPU the guest drains the queue
  // late and the rate comes out low (1942.9 kbit/s seen in CI, i.e. -2.9 %). Below, 10 % allows
  // for that and still tells netem's rate from none (8,300 kbit/s offered) and from a wrong unit.
  static void ExpectNetemRate(double wire_kbit, double rate_kbit) {
    EXPECT_LE(wire_kbit, rate_kbit * 1.02);
    EXPECT_GE(wire_kbit, rate_kbit * 0.90);
  }

  // Traffic back to a bare veth: everything arrives, in well under the smallest delay asked for.
  void ExpectUnimpaired(const GuestRecord& r) {
    EXPECT_EQ(r.Field("received"), r.Field("sent")) << r.Field("probe");
    EXPECT_LT(Num(r, "mean_ms"), 5.0) << r.Field("probe");
  }

  std::string dir_;
  std::string raw_;
  std::string scenario_;
  GuestConsole console_;
};

TEST_F(NetemGuest, MeshDelayJitterAndLossAsTheUserspacePath) {
  // network.mesh {delay_ms: 50, jitter_ms: 10, distribution: normal, loss: 0.05} on both agents,
  // 3,000 datagrams a -> b 1 ms apart: netem on a's egress delays and drops.
  ASSERT_NO_FATAL_FAILURE(Boot("mesh", /*timing=*/true));
  const GuestRecord* s = Probe("impaired");
  ASSERT_NE(s, nullptr);
  Print("50+-10 ms normal, loss 5%", *s);
  ASSERT_EQ(s->Field("sent"), "3000");
  ASSERT_GT(Num(*s, "received"), 2500.0);
  // The userspace test's tolerances (netemd_e2e_test.cpp): loss within 4 binomial sd (1.6 %); the
  // mean within 5 standard errors below (0.95 ms) and 5 + 3 ms of scheduling latency above; the sd
  // within 15 %.
  EXPECT_NEAR(Num(*s, "loss"), 0.05, 0.016);
  EXPECT_GT(Num(*s, "mean_ms"), 50.0 - 0.95);
  EXPECT_LT(Num(*s, "mean_ms"), 50.0 + 0.95 + 3.0) << Late(*s);
  EXPECT_NEAR(Num(*s, "sd_ms"), 10.0, 1.5) << Late(*s);
  // Undo: the veth's own qdisc back, traffic undelayed.
  EXPECT_EQ(Tree("undone"), Tree("pristine"));
  EXPECT_NE(Tree("applied").find("netem"), std::string::npos);
  const GuestRecord* after = Probe("after_undo");
  ASSERT_NE(after, nullptr);
  ExpectUnimpaired(*after);
}

TEST_F(NetemGuest, FixedDelayHasATightSpread) {
  ASSERT_NO_FATAL_FAILURE(Boot("fixed", /*timing=*/true));
  const GuestRecord* s = Probe("impaired");
  ASSERT_NE(s, nullptr);
  Print("fixed 50 ms", *s);
  ASSERT_EQ(s->Field("received"), s->Field("sent"));
  // As the userspace test: never early; the median within 2.5 ms (precision), the p99 within 40 ms
  // (only CPU starvation of the guest on a loaded host reaches it).
  EXPECT_GE(Num(*s, "min_ms"), 50.0);
  EXPECT_LT(Num(*s, "p50_ms"), 52.5) << Late(*s);
  EXPECT_LT(Num(*s, "p99_ms"), 90.0) << Late(*s);
}

TEST_F(NetemGuest, PerDestinationRuleDelaysAndLimitsOnlyThatPeer) {
  // A radio fault on a: {to: [c], delay_ms: 80, rate_kbit: 2000}: htb root, a class with netem for
  // c (u32 filter on c's address), the default class for the rest.
  ASSERT_NO_FATAL_FAILURE(Boot("per_destination", /*timing=*/true));
  const std::string applied = Tree("applied");
  EXPECT_NE(applied.find("qdisc htb 1:"), std::string::npos) << applied;
  EXPECT_NE(applied.find("delay 80ms rate 2Mbit"), std::string::npos) << applied;
  const GuestRecord* to_b = Probe("to_b");
  const GuestRecord* to_c = Probe("to_c");
  ASSERT_TRUE(to_b != nullptr && to_c != nullptr);
  Print("per-destination 80 ms, to b", *to_b);
  Print("per-destination 80 ms, to c", *to_c);
  ExpectUnimpaired(*to_b);
  EXPECT_EQ(to_c->Field("received"), to_c->Field("sent"));
  EXPECT_GE(Num(*to_c, "min_ms"), 80.0);
  EXPECT_LT(Num(*to_c, "p50_ms"), 82.5) << Late(*to_c);  // the userspace test's allowance
  // The rule's rate: 1000-byte datagrams offered at 8.3 Mbit/s queue behind netem's 2000 kbit/s,
  // which it counts on the whole frame (payload + UDP + IP + Ethernet = 1042 bytes). netem spaces
  // them by that exactly. See ExpectNetemRate for the band.
  const GuestRecord* rate = Probe("rate_to_c");
  ASSERT_NE(rate, nullptr);
  std::printf(
      "kernel netem (guest), per-destination rate 2000 kbit/s: %s kbit/s on the wire (%s of %s arrived)\n",
      rate->Field("wire_kbit").c_str(), rate->Field("received").c_str(), rate->Field("sent").c_str());
  EXPECT_EQ(rate->Field("received"), rate->Field("sent"));
  ExpectNetemRate(Num(*rate, "wire_kbit"), 2000.0);
  // The fault's removal leaves the veth as it was.
  EXPECT_EQ(Tree("removed"), Tree("pristine"));
  const GuestRecord* after = Probe("after_removal");
  ASSERT_NE(after, nullptr);
  ExpectUnimpaired(*after);
}

TEST_F(NetemGuest, RateLimitsEveryPacketOnTheLink) {
  // network.mesh {rate_kbit: 2000}: netem's own rate on the root qdisc, 400 datagrams of 1042
  // bytes on the wire offered at 8.3 Mbit/s; the default queue (1,000 packets) holds the backlog.
  ASSERT_NO_FATAL_FAILURE(Boot("rate", /*timing=*/false));
  const GuestRecord* rate = Probe("rate");
  ASSERT_NE(rate, nullptr);
  std::printf(
      "kernel netem (guest), rate 2000 kbit/s: %s kbit/s on the wire (%s of %s arrived, last after %s ms)\n",
      rate->Field("wire_kbit").c_str(), rate->Field("received").c_str(), rate->Field("sent").c_str(),
      rate->Field("max_ms").c_str());
  EXPECT_EQ(rate->Field("received"), rate->Field("sent"));
  ExpectNetemRate(Num(*rate, "wire_kbit"), 2000.0);
}

TEST_F(NetemGuest, ReorderSendsAFractionAtOnce) {
  // A radio fault {delay_ms: 10, reorder: 0.25}: netem sends 25 % at once (tc sets gap 1) and
  // delays the rest 10 ms, so the ones sent at once overtake those of the last 10 ms.
  ASSERT_NO_FATAL_FAILURE(Boot("reorder", /*timing=*/false));
  const GuestRecord* s = Probe("impaired");
  ASSERT_NE(s, nullptr);
  Print("10 ms, reorder 25%", *s);
  std::printf("  sent at once %.2f%% (25%%), arrived after a higher number %.2f%%\n", 100 * Num(*s, "early"),
              100 * Num(*s, "out_of_order"));
  EXPECT_EQ(s->Field("received"), s->Field("sent"));
  // Binomial with p = 0.25 over 3,000: sd 0.79 %; allow 4 sd.
  EXPECT_NEAR(Num(*s, "early"), 0.25, 0.032);
  // A delayed datagram is overtaken unless none of the ~10 sent after it within its 10 ms went at
  // once: 0.75 x (1 - 0.75^10) = 70.8 % of all at exactly 1 ms spacing, fewer when the guest's
  // sender falls behind (fewer datagrams per 10 ms). At most 75 %: the ones sent at once are not.
  EXPECT_GT(Num(*s, "out_of_order"), 0.5);
  EXPECT_LE(Num(*s, "out_of_order"), 0.75);
}

TEST_F(NetemGuest, DuplicationSendsASecondCopy) {
  // network.mesh {delay_ms: 5, duplicate: 0.1}.
  ASSERT_NO_FATAL_FAILURE(Boot("duplicate", /*timing=*/false));
  const GuestRecord* s = Probe("impaired");
  ASSERT_NE(s, nullptr);
  const double ratio = Num(*s, "datagrams") / Num(*s, "sent");
  std::printf(
      "kernel netem (guest), duplicate 10%% (delay 5 ms): sent %s, b received %s datagrams (%.2f%%) of %s "
      "distinct numbers\n",
      s->Field("sent").c_str(), s->Field("datagrams").c_str(), 100 * ratio, s->Field("received").c_str());
  EXPECT_EQ(s->Field("received"), s->Field("sent"));  // nothing lost
  // Binomial with p = 0.1 over 3,000: sd of the extra fraction 0.55 %; allow 4 sd (as userspace).
  EXPECT_NEAR(ratio, 1.1, 0.022);
  EXPECT_EQ(Tree("undone"), Tree("pristine"));
  const GuestRecord* after = Probe("after_undo");
  ASSERT_NE(after, nullptr);
  EXPECT_EQ(after->Field("datagrams"), after->Field("sent"));
}

TEST_F(NetemGuest, CorruptionFlipsABitThatTheReceiversChecksumsCatch) {
  // network.mesh {corrupt: 0.1}. netem flips one random bit of the first skb_headlen bytes of 10 %
  // of the packets, after the route and after computing any offloaded checksum: here the whole
  // 58-byte frame (Ethernet 14 + IP 20 + UDP 8 + payload 16 = 464 bits). Where the bit lands:
  //   source MAC (48 bits) and the destination's group bit (1): delivered intact (veth does not
  //     filter on the source; a group address is taken as multicast, and IP accepts it);
  //   the other 47 destination MAC bits: b's stack drops it as for another host;
  //   EtherType (16): no protocol takes it;
  //   IP header (160) and UDP header + payload (192): the checksums catch it (Ip InHdrErrors,
  //     Udp InErrors).
  // So 10 % x 415/464 = 8.94 % go missing (delivered 91.06 %) and 352/415 = 84.8 % of the missing
  // show in b's error counters. (The userspace daemon flips a bit of the 44-byte IP packet before
  // routing: 90 % delivered and 90.9 % of the missing counted; netemd_e2e_test.cpp.)
  ASSERT_NO_FATAL_FAILURE(Boot("corrupt", /*timing=*/false));
  const GuestRecord* s = Probe("impaired");
  ASSERT_NE(s, nullptr);
  const double sent = Num(*s, "sent");
  const double delivered = Num(*s, "received") / sent;
  const double missing = sent - Num(*s, "received");
  const double refused = Num(*s, "receive_errors");
  std::printf(
      "kernel netem (guest), corrupt 10%%: sent %.0f received %s (%.2f%%, model 91.06%%); of the %.0f "
      "missing "
      "%.1f%% refused by b's stack (model 84.8%%)\n",
      sent, s->Field("received").c_str(), 100 * delivered, missing, 100 * refused / missing);
  // Binomial over 3,000 with p = 0.0894: sd 0.52 %; allow 4 sd (the userspace test's 2.2 %).
  EXPECT_NEAR(delivered, 1.0 - 0.1 * 415.0 / 464.0, 0.022);
  // Binomial over ~270 missing: sd 2.2 %; allow 4 sd.
  ASSERT_GT(missing, 0.0);
  EXPECT_NEAR(refused / missing, 352.0 / 415.0, 0.088);
  const GuestRecord* after = Probe("after_undo");
  ASSERT_NE(after, nullptr);
  ExpectUnimpaired(*after);
}

TEST_F(NetemGuest, GilbertElliottLossComesInBursts) {
  // A radio fault {delay_ms: 5, gilbert_elliott: {p: 0.02, r: 0.25, loss_bad: 1.0, loss_good: 0}}:
  // netem "loss gemodel 2% 25% 100% 0%", bad spells of 1/r = 4 packets, 7.41 % in the long run.
  ASSERT_NO_FATAL_FAILURE(Boot("gilbert_elliott", /*timing=*/false));
  const GuestRecord* s = Probe("impaired");
  ASSERT_NE(s, nullptr);
  std::printf(
      "kernel netem (guest), Gilbert-Elliott p 2%% r 25%% loss_bad 100%%: sent %s received %s loss %.2f%% "
      "(stationary 7.41%%), %s bursts, mean burst %s packets (model 4)\n",
      s->Field("sent").c_str(), s->Field("received").c_str(), 100 * Num(*s, "loss"),
      s->Field("bursts").c_str(), s->Field("mean_burst").c_str());
  // The userspace test's tolerances: the Markov chain's loss estimate has sd 1.2 % over 3,000
  // packets (4 sd); the mean of ~55 geometric bursts of mean 4 has sd ~0.47 (4.0 +- 2).
  EXPECT_NEAR(Num(*s, "loss"), 0.0741, 0.048);
  EXPECT_NEAR(Num(*s, "mean_burst"), 4.0, 2.0);
}

TEST_F(NetemGuest, PartitionCutsOneWayAndHeals) {
  // partition {groups: [[a], [b]], oneway: true}: b drops what comes from a (PlanPartition's
  // iptables chain on b's INPUT); healing removes exactly that chain.
  ASSERT_NO_FATAL_FAILURE(Boot("partition", /*timing=*/false));
  const std::string cut = Tree("iptables_cut", "b");
  EXPECT_NE(cut.find("-A SWARMBOX-PART-3 -s 10.213.7.1/32 -j DROP"), std::string::npos) << cut;
  const GuestRecord* during = Probe("cut");
  const GuestRecord* healed = Probe("healed");
  ASSERT_TRUE(during != nullptr && healed != nullptr);
  EXPECT_EQ(during->Field("sent"), "100");  // the sender sees no error: the drop is on b's ingress
  EXPECT_EQ(during->Field("received"), "0");
  EXPECT_EQ(Tree("iptables_healed", "b").find("SWARMBOX"), std::string::npos);
  ExpectUnimpaired(*healed);
}

TEST_F(NetemGuest, ReplaceAndRemovalLeaveTheQdiscTreeAsItWas) {
  // network.mesh {delay_ms: 20}; a radio fault for c only {to: [c], delay_ms: 80} pushed and popped;
  // then an all-traffic fault {delay_ms: 30} pushed and popped; the injector's PlanRadioChange each
  // time. The mesh plan is also applied twice (tc qdisc replace over itself).
  ASSERT_NO_FATAL_FAILURE(Boot("replace", /*timing=*/true));
  const std::string mesh = Tree("mesh");
  EXPECT_NE(mesh.find("delay 20ms"), std::string::npos) << mesh;
  EXPECT_EQ(Tree("mesh_again"), mesh);
  EXPECT_NE(Tree("fade_c").find("delay 80ms"), std::string::npos);
  EXPECT_EQ(Tree("fade_c_removed"), mesh);
  EXPECT_NE(Tree("storm").find("delay 30ms"), std::string::npos);
  EXPECT_EQ(Tree("storm_removed"), mesh);
  EXPECT_EQ(Tree("undone"), Tree("pristine"));
  // What each tree did to the traffic: never early, the median within the userspace allowance.
  struct Expect {
    const char* probe;
    double delay_ms;
  };
  for (const Expect& e : {Expect{"mesh_to_b", 20}, Expect{"fade_c_to_b", 20}, Expect{"fade_c_to_c", 80},
                          Expect{"fade_c_removed_to_c", 20}, Expect{"storm_to_b", 30}}) {
    const GuestRecord* r = Probe(e.probe);
    ASSERT_NE(r, nullptr);
    Print(e.probe, *r);
    EXPECT_EQ(r->Field("received"), r->Field("sent")) << e.probe;
    EXPECT_GE(Num(*r, "min_ms"), e.delay_ms) << e.probe;
    EXPECT_LT(Num(*r, "p50_ms"), e.delay_ms + 2.5) << Late(*r);
  }
  const GuestRecord* undone = Probe("undone_to_b");
  ASSERT_NE(undone, nullptr);
  ExpectUnimpaired(*undone);
}

}  // namespace
}  // namespace swarmbox::netem_guest
