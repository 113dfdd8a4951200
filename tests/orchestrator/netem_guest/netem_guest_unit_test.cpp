// The netem guest's pure parts: modules.dep load order, the console records, the measurements the
// guest reports, the tc listing normalization, the UML command line, and the probe's /proc/net/snmp
// reader.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "guest_console.hpp"
#include "guest_measurements.hpp"
#include "kernel_modules.hpp"
#include "udp_probe.hpp"
#include "uml_guest.hpp"

namespace swarmbox::netem_guest {
namespace {

using faults::testing::ProbeArrival;
using faults::testing::ProbeSample;

constexpr const char* kModulesDep =
    "kernel/net/sched/sch_netem.ko:\n"
    "kernel/drivers/net/veth.ko:\n"
    "kernel/net/ipv4/netfilter/iptable_filter.ko: kernel/net/ipv4/netfilter/ip_tables.ko "
    "kernel/net/netfilter/x_tables.ko\n"
    "kernel/net/ipv4/netfilter/ip_tables.ko: kernel/net/netfilter/x_tables.ko\n"
    "kernel/net/netfilter/x_tables.ko:\n"
    "kernel/net/netfilter/xt_TEE.ko: kernel/net/ipv4/netfilter/nf-dup-ipv4.ko "
    "kernel/net/netfilter/x_tables.ko\n";

TEST(ModuleName, IsTheFileNameWithoutKoAndWithUnderscores) {
  EXPECT_EQ(ModuleName("kernel/net/sched/sch_netem.ko"), "sch_netem");
  EXPECT_EQ(ModuleName("kernel/net/ipv4/netfilter/nf-dup-ipv4.ko"), "nf_dup_ipv4");
  EXPECT_EQ(ModuleName("kernel/drivers/net/veth.ko.xz"), "veth");
  EXPECT_EQ(ModuleName("veth"), "veth");
}

TEST(ModuleLoadOrder, PutsDependenciesFirstAndEachModuleOnce) {
  auto order = ModuleLoadOrder(kModulesDep, {"veth", "iptable_filter", "ip_tables", "sch_netem"});
  ASSERT_TRUE(order) << order.error().ToString();
  EXPECT_EQ(*order, (std::vector<std::string>{
                        "kernel/drivers/net/veth.ko", "kernel/net/netfilter/x_tables.ko",
                        "kernel/net/ipv4/netfilter/ip_tables.ko",
                        "kernel/net/ipv4/netfilter/iptable_filter.ko", "kernel/net/sched/sch_netem.ko"}));
}

TEST(ModuleLoadOrder, NamesAModuleTheTreeDoesNotHave) {
  auto missing = ModuleLoadOrder(kModulesDep, {"sch_htb"});
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code(), ErrorCode::kNotFound);
  EXPECT_EQ(missing.error().message(), "module sch_htb is not in modules.dep");
  auto needed = ModuleLoadOrder(kModulesDep, {"xt_TEE"});
  ASSERT_FALSE(needed);
  EXPECT_EQ(needed.error().message(), "module nf_dup_ipv4 (needed by xt_TEE) is not in modules.dep");
}

TEST(ModuleLoadOrder, RefusesALineWithoutAColon) {
  auto bad = ModuleLoadOrder("kernel/a.ko:\nkernel/b.ko\n", {"a"});
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message(), "modules.dep line 2 has no ':'");
}

TEST(LoadModules, RefusesACompressedModule) {
  Status s = LoadModules("/nonexistent", {"kernel/drivers/net/veth.ko.xz"});
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code(), ErrorCode::kInvalidArgument);
}

TEST(GuestConsole, KeepsOnlyTheGuestsRecordsAndRoundTripsText) {
  const std::string tree = "qdisc netem 8001: root refcnt 2 limit 1000 delay 50ms\nqdisc \"x\" y=z\n";
  const std::string console =
      "Linux version 6.1.176\r\n" + GuestLine(1.5, kEventReady, {{"kernel", "6.1.176"}, {"modules", "7"}}) +
      "\r\n" + "netem: version 1.3 " +
      GuestLine(2.0, kEventTree, {{"scenario", "mesh"}, {"stage", "applied"}, {"text", tree}}) + "\n" +
      "t=3.000 node=physics event=ready\n" +
      GuestLine(4.0, kEventMeasured, {{"scenario", "mesh"}, {"probe", "impaired"}, {"mean_ms", "50.4"}}) +
      "\n" + GuestLine(5.0, kEventError, {{"scenario", "rate"}, {"message", "`tc` exited 2"}}) + "\n" +
      GuestLine(6.0, kEventDone, {{"scenarios", "2"}, {"errors", "1"}});
  const GuestConsole c = ParseGuestConsole(console);
  ASSERT_EQ(c.records.size(), 5u);
  EXPECT_EQ(c.records[0].event, "ready");
  EXPECT_EQ(c.records[0].Field("modules"), "7");  // the carriage return is not part of the value
  const GuestRecord* t = c.Find(kEventTree, {{"scenario", "mesh"}, {"stage", "applied"}});
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->Field("text"), tree);
  EXPECT_EQ(c.Find(kEventTree, {{"scenario", "mesh"}, {"stage", "undone"}}), nullptr);
  const GuestRecord* m = c.Find(kEventMeasured, {{"probe", "impaired"}});
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->Field("mean_ms"), "50.4");
  EXPECT_EQ(m->Field("absent"), "");
  EXPECT_TRUE(c.done());
  EXPECT_EQ(c.Errors(), "rate: `tc` exited 2\n");
}

TEST(GuestConsole, LongestStallIsTheLatestSenderOfAnyProbe) {
  const GuestConsole c = ParseGuestConsole(
      GuestLine(1.0, kEventMeasured, {{"probe", "to_b"}, {"send_late_max_ms", "3.5"}}) + "\n" +
      GuestLine(2.0, kEventMeasured, {{"probe", "to_c"}, {"send_late_max_ms", "341.2"}}) + "\n" +
      GuestLine(3.0, kEventTree, {{"stage", "applied"}, {"send_late_max_ms", "999"}}) + "\n");
  EXPECT_EQ(c.LongestStall(), (std::pair<double, std::string>{341.2, "to_c"}));
  EXPECT_EQ(ParseGuestConsole("").LongestStall(), (std::pair<double, std::string>{0.0, ""}));
}

TEST(GuestConsole, IsNotDoneWithoutTheDoneRecord) {
  const GuestConsole c =
      ParseGuestConsole(GuestLine(1.0, kEventReady, {}) + "\nKernel panic - not syncing\n");
  EXPECT_FALSE(c.done());
  EXPECT_EQ(c.Errors(), "");
}

ProbeSample Sample(std::uint32_t sent, const std::vector<std::pair<std::uint32_t, double>>& arrivals) {
  ProbeSample s;
  s.sent = sent;
  std::map<std::uint32_t, double> distinct;
  std::int64_t t = 0;
  for (const auto& [seq, delay] : arrivals) {
    s.arrivals.push_back(ProbeArrival{seq, delay, t});
    t += 1000;
    distinct[seq] = delay;
    ++s.datagrams;
  }
  for (const auto& [seq, delay] : distinct) {
    s.seqs.push_back(seq);
    s.delay_ms.push_back(delay);
  }
  return s;
}

TEST(SampleFields, ReportsCountsLossAndTheDelayDistribution) {
  const ProbeSample s = Sample(5, {{0, 10.0}, {1, 20.0}, {3, 30.0}, {3, 31.0}});
  const Fields f = SampleFields(s);
  auto field = [&](const std::string& k) {
    auto it = std::find_if(f.begin(), f.end(), [&](const auto& kv) { return kv.first == k; });
    return it == f.end() ? std::string("<none>") : it->second;
  };
  EXPECT_EQ(field("sent"), "5");
  EXPECT_EQ(field("received"), "3");
  EXPECT_EQ(field("datagrams"), "4");
  EXPECT_EQ(field("loss"), "0.40000");
  EXPECT_EQ(field("mean_ms"), "20.333");
  EXPECT_EQ(field("min_ms"), "10.000");
  EXPECT_EQ(field("p50_ms"), "20.000");
  EXPECT_EQ(field("max_ms"), "31.000");
  // Nothing received: counts only.
  EXPECT_EQ(field("send_late_max_ms"), "0.000");
  EXPECT_EQ(SampleFields(Sample(3, {})).size(), 5u);
}

TEST(CountLossBursts, CountsRunsOfConsecutiveLostNumbers) {
  // 0 1 _ _ 4 _ 6 _ _ _ (10 sent): bursts {2,3}, {5}, {7,8,9}.
  const LossBursts b = CountLossBursts(Sample(10, {{0, 1}, {1, 1}, {4, 1}, {6, 1}}));
  EXPECT_EQ(b.bursts, 3);
  EXPECT_DOUBLE_EQ(b.mean_length, 2.0);
  EXPECT_EQ(CountLossBursts(Sample(2, {{0, 1}, {1, 1}})).bursts, 0);
}

TEST(EarlyFraction, CountsTheNumbersUnderTheThreshold) {
  EXPECT_DOUBLE_EQ(EarlyFraction(Sample(4, {{0, 10.1}, {1, 0.05}, {2, 10.2}, {3, 0.04}}), 5.0), 0.5);
  EXPECT_DOUBLE_EQ(EarlyFraction(Sample(4, {}), 5.0), 0.0);
}

TEST(OutOfOrderFraction, CountsArrivalsAfterAHigherNumberAndIgnoresSecondCopies) {
  // Arrival order 0 3 1 2 4 3(copy) 5: 1 and 2 came after 3.
  const ProbeSample s = Sample(6, {{0, 1}, {3, 1}, {1, 1}, {2, 1}, {4, 1}, {3, 1}, {5, 1}});
  EXPECT_DOUBLE_EQ(OutOfOrderFraction(s), 2.0 / 6.0);
  EXPECT_DOUBLE_EQ(OutOfOrderFraction(Sample(3, {{0, 1}, {1, 1}, {2, 1}})), 0.0);
}

TEST(ArrivalRateKbit, IsTheFittedSpacingOfTheArrivals) {
  // 1042-byte frames every 4.168 ms: 2000 kbit/s; one arrival 30 ms late barely moves the fit.
  ProbeSample s;
  for (std::uint32_t i = 0; i < 300; ++i) {
    const auto t = static_cast<std::int64_t>(i) * 4168 + (i == 150 ? 30000 : 0);
    s.arrivals.push_back({i, 0.0, t});
  }
  auto kbit = ArrivalRateKbit(s, 1042);
  ASSERT_TRUE(kbit);
  EXPECT_NEAR(*kbit, 2000.0, 1.0);
  s.arrivals.resize(1);
  EXPECT_FALSE(ArrivalRateKbit(s, 1042));
}

TEST(NormalizeTcListing, MasksTheKernelsOwnHandlesAndCounters) {
  EXPECT_EQ(NormalizeTcListing("qdisc netem 8001: root refcnt 2 limit 1000 delay 20ms\n"),
            "qdisc netem auto: root refcnt 2 limit 1000 delay 20ms\n");
  EXPECT_EQ(NormalizeTcListing("qdisc netem 800f: root refcnt 2 limit 1000 delay 20ms\n"),
            NormalizeTcListing("qdisc netem 8011: root refcnt 2 limit 1000 delay 20ms\n"));
  // Handles the plan chose stay: they are part of the tree.
  EXPECT_EQ(NormalizeTcListing("qdisc netem 110: parent 1:10 limit 1000 delay 80ms\n"),
            "qdisc netem 110: parent 1:10 limit 1000 delay 80ms\n");
  EXPECT_EQ(NormalizeTcListing("qdisc noqueue 0: root refcnt 2 \n"), "qdisc noqueue 0: root refcnt 2 \n");
  EXPECT_EQ(NormalizeTcListing(
                "qdisc htb 1: root refcnt 2 r2q 10 default 0x1 direct_packets_stat 7 direct_qlen 1000"),
            "qdisc htb 1: root refcnt 2 r2q 10 default 0x1 direct_qlen 1000");
}

TEST(UmlArgv, BootsTheHostRootReadOnlyWithTheGuestAsInit) {
  GuestBoot boot;
  boot.kernel = "/usr/bin/linux.uml";
  boot.init = "/build/swarmbox-netem-guest";
  boot.scratch_dir = "/tmp/g";
  boot.scenarios = {"mesh", "rate"};
  const std::vector<std::string> argv = UmlArgv(boot);
  ASSERT_FALSE(argv.empty());
  EXPECT_EQ(argv[0], "/usr/bin/linux.uml");
  auto has = [&](const std::string& a) { return std::find(argv.begin(), argv.end(), a) != argv.end(); };
  for (const char* a :
       {"mem=256M", "rootfstype=hostfs", "rootflags=/", "ro", "init=/build/swarmbox-netem-guest",
        "uml_dir=/tmp/g", "con0=null,fd:1", "con=null", "ssl=null"}) {
    EXPECT_TRUE(has(a)) << a;
  }
  // The init's own arguments come after "--", the scenarios last, in order.
  const auto dashes = std::find(argv.begin(), argv.end(), "--");
  ASSERT_NE(dashes, argv.end());
  EXPECT_EQ(std::vector<std::string>(dashes + 1, argv.end()),
            (std::vector<std::string>{"--modules", "/usr/lib/uml/modules", "--scenario", "mesh", "--scenario",
                                      "rate"}));
}

TEST(SnmpReceiveErrors, AddsIpHeaderErrorsAndUdpErrors) {
  const char* snmp =
      "Ip: Forwarding DefaultTTL InReceives InHdrErrors InAddrErrors\n"
      "Ip: 1 64 3300 17 0\n"
      "Icmp: InMsgs InErrors\n"
      "Icmp: 5 4\n"
      "Udp: InDatagrams NoPorts InErrors OutDatagrams\n"
      "Udp: 3000 0 205 0\n";
  EXPECT_EQ(faults::testing::SnmpReceiveErrors(snmp), 222);
  EXPECT_EQ(faults::testing::SnmpReceiveErrors(""), 0);
}

}  // namespace
}  // namespace swarmbox::netem_guest
