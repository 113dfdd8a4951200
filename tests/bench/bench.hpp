// swarmbox-bench: one executable, benchmark suites as sub-commands.
//
// A suite is a function that runs its scenarios and prints one logfmt line of figures per
// scenario on stdout (`suite=bus scenario=rtt_small backend=cyclonedds p50_us=... p99_us=...`).
// Suites register themselves from their own source file, which the component's tests/ CMake file
// adds to the swarmbox-bench target:
//
//   SWARMBOX_BENCH_SUITE(bus, "DDS round-trip latency and throughput per backend", RunBusBench);
//   int RunBusBench(const swarmbox::bench::Args& args) { ...; return 0; }
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace swarmbox::bench {

// Sub-command arguments: `--key=value` or `--key value` pairs, and positionals.
struct Args {
  std::map<std::string, std::string> options;
  std::vector<std::string> positionals;
  bool quick = false;  // --quick: smaller scenarios, for smoke tests in CI

  std::string Get(std::string_view key, std::string_view fallback) const;
  double GetDouble(std::string_view key, double fallback) const;
  long GetInt(std::string_view key, long fallback) const;
};

using SuiteFn = int (*)(const Args&);

struct Suite {
  std::string name;
  std::string description;
  SuiteFn run;
};

bool RegisterSuite(Suite suite);
const std::vector<Suite>& Suites();

}  // namespace swarmbox::bench

#define SWARMBOX_BENCH_SUITE(name, description, fn)           \
  static const bool swarmbox_bench_registered_##name =        \
      ::swarmbox::bench::RegisterSuite({#name, description, fn})
