// swarmbox-microbench: Google Benchmark micro-benchmarks of the orchestrator's per-log-line path.
// Every line every container of a trial writes goes through the Docker log demultiplexer, then
// the end-condition matcher (ECMAScript regexes, runner/end_matcher.hpp) and logfmt parsing (the
// monitor, the metrics). A 20-drone SAR trial at rtf 0 writes thousands of lines per second, so
// these set how many trials one orchestrator thread can watch. Pure functions, no I/O.
//
//   build/tests/bench/swarmbox-microbench                          # full run
//   build/tests/bench/swarmbox-microbench --benchmark_min_time=0.01   # the ctest smoke run
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/docker/log_demux.hpp"
#include "swarmbox/runner/end_matcher.hpp"

namespace {

using swarmbox::dsl::EndCondition;
using swarmbox::dsl::Outcome;

// Lines as the agents and the physics server write them (most are link and clock lines).
const std::vector<std::string>& SampleLines() {
  static const std::vector<std::string> lines = {
      "t=12.340 node=scout_1 event=link peer=scout_2 rtt_ms=201.4 loss=0.050 sent=60 lost=3",
      "t=12.350 node=physics event=clock sim_s=12.350 rtf=3.912 steps=12350",
      "t=12.400 node=scout_2 event=sighting victim=1 x=41.20 y=-12.75 confidence=0.91",
      "t=12.450 node=lifter event=stage stage=\"carry home\" payload_kg=80.0 battery=0.62",
  };
  return lines;
}

// The end conditions of trials/sar_search.yaml.
const swarmbox::runner::EndMatcher& SarMatcher() {
  static const swarmbox::runner::EndMatcher matcher = [] {
    auto m = swarmbox::runner::EndMatcher::Compile(
        {EndCondition{"event=mission_complete", Outcome::kSuccess, "", ""},
         EndCondition{"event=collision", Outcome::kFailure, "collision", ""},
         EndCondition{"event=crash", Outcome::kFailure, "crash", ""}});
    if (!m) std::abort();
    return *std::move(m);
  }();
  return matcher;
}

void BM_ParseLogfmt(benchmark::State& state) {
  const auto& lines = SampleLines();
  std::size_t i = 0, bytes = 0;
  for (auto _ : state) {
    const std::string& line = lines[i++ % lines.size()];
    benchmark::DoNotOptimize(swarmbox::ParseLogfmt(line));
    bytes += line.size();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ParseLogfmt);

void BM_EndMatcherNoMatch(benchmark::State& state) {
  const auto& matcher = SarMatcher();
  const auto& lines = SampleLines();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(matcher.Match("scout_1", lines[i++ % lines.size()]));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EndMatcherNoMatch);

void BM_LogEventFormat(benchmark::State& state) {
  for (auto _ : state) {
    swarmbox::LogEvent e(12.34, "scout_1", "link");
    e.Add("peer", "scout_2").Add("rtt_ms", 201.4, 1).Add("loss", 0.05).Add("sent", 60);
    benchmark::DoNotOptimize(e.str().data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LogEventFormat);

// Docker's multiplexed stream: 8-byte frame headers, one line per frame, fed in 16 KiB chunks
// (libcurl's usual write size).
void BM_LogDemuxMultiplexed(benchmark::State& state) {
  std::string stream;
  while (stream.size() < (1U << 20)) {
    for (const std::string& l : SampleLines()) {
      const std::string payload = l + "\n";
      const auto n = static_cast<std::uint32_t>(payload.size());
      stream += std::string{'\x01', '\0', '\0', '\0', static_cast<char>(n >> 24U),
                            static_cast<char>((n >> 16U) & 0xFFU),
                            static_cast<char>((n >> 8U) & 0xFFU), static_cast<char>(n & 0xFFU)};
      stream += payload;
    }
  }
  constexpr std::size_t kChunk = 16 * 1024;
  std::size_t lines = 0;
  for (auto _ : state) {
    swarmbox::docker::LogDemuxer demux(swarmbox::docker::LogDemuxer::Mode::kMultiplexed,
                                       [&](const swarmbox::docker::LogLine&) { ++lines; });
    for (std::size_t at = 0; at < stream.size(); at += kChunk) {
      benchmark::DoNotOptimize(demux.Feed(std::string_view(stream).substr(at, kChunk)));
    }
    benchmark::DoNotOptimize(demux.Finish());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(stream.size()));
  state.counters["lines"] = benchmark::Counter(static_cast<double>(lines), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_LogDemuxMultiplexed)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
