// swarmbox-bench mcap: what writing and reading a recording costs. N small JSON messages shaped
// like the recording's /drones/<d>/truth (~220 bytes each, 10 drones at 10 Hz of simulated time)
// go through McapWriter into a file in /tmp, then McapReader::ForEach reads them back. One logfmt
// line per compression:
//   suite=mcap scenario=truth_json compression=zstd messages=100000 json_mb=22.1 file_mb=2.9
//   ratio=7.6 write_mb_s=... write_cpu_ns_per_msg=... read_mb_s=...
// *_mb_s = uncompressed JSON MB per wall-clock second (MB = 1e6 bytes); *_cpu_* = process CPU
// time. Figures are printed, never asserted. --quick: 10,000 messages. --messages=N;
// --compression=zstd|lz4|none (default: all three); --chunk-kb=K (default 1024).
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include "bench.hpp"
#include "swarmbox/record/foxglove_schemas.hpp"
#include "swarmbox/record/mcap.hpp"

namespace {

using namespace swarmbox::record;

double CpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}
double WallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string TruthJson(std::uint64_t i, std::uint64_t t_ns, int drone) {
  const double s = static_cast<double>(i) * 0.01;
  char buf[320];
  std::snprintf(buf, sizeof buf,
                R"({"timestamp":%s,"drone":"scout_%d","position":[%.3f,%.3f,%.3f],"velocity":[%.3f,%.3f,%.3f],)"
                R"("orientation":{"x":%.5f,"y":%.5f,"z":%.5f,"w":%.5f}})",
                JsonTimestamp(t_ns).c_str(), drone, 10.0 + s, -4.0 + 0.5 * s, 30.0 + 0.01 * s, 5.0, 0.25, 0.001,
                0.001 * s, -0.002, 0.3, 0.95);
  return buf;
}

int RunMcapBench(const swarmbox::bench::Args& args) {
  const auto messages = static_cast<std::uint64_t>(args.GetInt("messages", args.quick ? 10000 : 100000));
  const std::string only = args.Get("compression", "");
  McapOptions base;
  base.chunk_bytes = static_cast<std::size_t>(args.GetInt("chunk-kb", 1024)) << 10;

  constexpr int kDrones = 10;
  std::vector<std::string> payloads;
  payloads.reserve(messages);
  std::uint64_t json_bytes = 0;
  for (std::uint64_t i = 0; i < messages; ++i) {
    payloads.push_back(TruthJson(i, (i / kDrones) * 100'000'000, static_cast<int>(i % kDrones)));
    json_bytes += payloads.back().size();
  }
  const std::string path =
      (std::filesystem::temp_directory_path() / ("swarmbox-mcap-bench-" + std::to_string(getpid()) + ".mcap")).string();

  for (Compression c : {Compression::kZstd, Compression::kLz4, Compression::kNone}) {
    if (!only.empty() && only != CompressionName(c)) continue;
    McapOptions options = base;
    options.compression = c;
    const double w0 = WallSeconds();
    const double c0 = CpuSeconds();
    auto writer = McapWriter::Create(path, options);
    if (!writer) {
      std::fprintf(stderr, "mcap bench: %s\n", writer.error().ToString().c_str());
      return 1;
    }
    std::vector<ChannelId> ids;
    for (int d = 0; d < kDrones; ++d) {
      ids.push_back(*(*writer)->AddChannel(MakeChannel("/drones/scout_" + std::to_string(d) + "/truth", kDroneTruth)));
    }
    for (std::uint64_t i = 0; i < messages; ++i) {
      if (auto s = (*writer)->Write(ids[i % kDrones], (i / kDrones) * 100'000'000, payloads[i]); !s) {
        std::fprintf(stderr, "mcap bench: %s\n", s.error().ToString().c_str());
        return 1;
      }
    }
    if (auto s = (*writer)->Close(); !s) {
      std::fprintf(stderr, "mcap bench: %s\n", s.error().ToString().c_str());
      return 1;
    }
    const double write_wall = WallSeconds() - w0;
    const double write_cpu = CpuSeconds() - c0;
    const auto file_bytes = std::filesystem::file_size(path);

    const double r0 = WallSeconds();
    auto reader = McapReader::Open(path);
    std::uint64_t read = 0;
    if (!reader || !reader->ForEach([&](const McapMessage&) { ++read; }) || read != messages) {
      std::fprintf(stderr, "mcap bench: reading back failed (%llu of %llu messages)\n",
                   static_cast<unsigned long long>(read), static_cast<unsigned long long>(messages));
      return 1;
    }
    const double read_wall = WallSeconds() - r0;
    const double json_mb = static_cast<double>(json_bytes) / 1e6;
    std::printf(
        "suite=mcap scenario=truth_json compression=%s messages=%llu chunk_kb=%zu json_mb=%.2f file_mb=%.3f "
        "ratio=%.2f write_s=%.3f write_mb_s=%.1f write_cpu_ns_per_msg=%.0f read_s=%.3f read_mb_s=%.1f\n",
        std::string(CompressionName(c)).c_str(), static_cast<unsigned long long>(messages), base.chunk_bytes >> 10,
        json_mb, static_cast<double>(file_bytes) / 1e6, static_cast<double>(json_bytes) / static_cast<double>(file_bytes),
        write_wall, json_mb / write_wall, write_cpu * 1e9 / static_cast<double>(messages), read_wall,
        json_mb / read_wall);
    std::fflush(stdout);
  }
  std::filesystem::remove(path);
  return 0;
}

}  // namespace

SWARMBOX_BENCH_SUITE(mcap, "MCAP recording: write and read throughput, size per compression", RunMcapBench);
