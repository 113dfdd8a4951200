// swarmbox-bench radio: the simulated radio channel (swarmbox::channel) under a swarm's broadcast
// load. N drones fly lawnmower legs at 5 m/s over a square area (the SAR search's 200 m field by
// default), each broadcasting a DroneState-sized frame at 10 Hz, the channel stepped in 4 ms
// lockstep steps for sim_s simulated seconds. One logfmt line per size:
//   suite=radio scenario=broadcast_10hz profile=... drones=N sim_s=60 deliveries=...
//   deliveries_per_s=... cpu_ns_per_delivery=... rtf_cpu=... medium_util=... lost_*=...
// deliveries_per_s = deliveries per wall-clock second; rtf_cpu = simulated s per CPU s spent in
// the channel alone (how far from limiting a trial it is). Figures are printed, never asserted.
// --quick: 2 s of simulated time. --drones=N runs only N; --sim-s=S; --area-m=A (square side);
// --profile=NAME (trials/radios/NAME.yaml, default wifi_5ghz_mesh); --frame-bytes=B (default 120).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "bench.hpp"
#include "swarmbox/channel/channel.hpp"

namespace {

using namespace swarmbox::channel;

struct Scenario {
  std::size_t drones = 10;
  double sim_s = 60;
  double area_m = 200;
  std::uint32_t frame_bytes = 120;
};

// Drone i flies east-west legs 5 m/s in its own lane of the area, starting at a spread phase.
Vec3d Position(std::size_t i, std::size_t n, double area_m, double t_s) {
  const double lane = area_m / static_cast<double>(n);
  const double leg_s = area_m / 5.0;
  const double phase = t_s + static_cast<double>(i) * 7.3;
  const double along = std::fmod(phase, 2 * leg_s);
  const double x = along < leg_s ? along * 5.0 : (2 * leg_s - along) * 5.0;
  return {x - area_m / 2, (static_cast<double>(i) + 0.5) * lane - area_m / 2, 30.0 + static_cast<double>(i % 3) * 5.0};
}

int RunScenario(const RadioProfile& profile, const Scenario& sc) {
  Channel ch(profile, sc.drones, 42, {});
  constexpr std::int64_t kStepNs = 4'000'000;
  constexpr std::int64_t kStepsPerFrame = 25;  // 10 Hz
  const auto steps = static_cast<std::int64_t>(std::llround(sc.sim_s * 1e9 / kStepNs));
  std::vector<Vec3d> pos(sc.drones);
  std::vector<Delivery> got;
  got.reserve(sc.drones * sc.drones);
  std::uint64_t deliveries = 0;
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  for (std::int64_t k = 0; k <= steps; ++k) {
    const std::int64_t t = k * kStepNs;
    for (std::size_t i = 0; i < sc.drones; ++i) pos[i] = Position(i, sc.drones, sc.area_m, static_cast<double>(t) * 1e-9);
    ch.SetPositions(pos);
    got.clear();
    ch.TakeDeliveries(t, &got);
    deliveries += got.size();
    for (std::size_t i = 0; i < sc.drones; ++i) {
      // Each drone's 10 Hz broadcast at its own phase of the 100 ms period.
      if ((k + static_cast<std::int64_t>(i)) % kStepsPerFrame != 0) continue;
      Packet p;
      p.from = i;
      p.seq = static_cast<std::uint64_t>(k / kStepsPerFrame);
      p.size_bytes = sc.frame_bytes;
      p.sent_ns = t;
      ch.Send(t, p);
    }
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu_s = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  const ChannelStats& s = ch.stats();
  const double denom = static_cast<double>(std::max<std::uint64_t>(deliveries, 1));
  std::printf(
      "suite=radio scenario=broadcast_10hz profile=%s drones=%zu sim_s=%.1f area_m=%.0f frame_bytes=%u "
      "wall_s=%.3f cpu_s=%.3f sent=%llu deliveries=%llu deliveries_per_s=%.0f cpu_ns_per_delivery=%.0f "
      "rtf_cpu=%.1f medium_util=%.3f lost_per=%llu lost_range=%llu lost_queue=%llu\n",
      profile.name.c_str(), sc.drones, sc.sim_s, sc.area_m, sc.frame_bytes, wall_s, cpu_s,
      static_cast<unsigned long long>(s.sent), static_cast<unsigned long long>(deliveries),
      static_cast<double>(deliveries) / wall_s, cpu_s * 1e9 / denom, sc.sim_s / std::max(cpu_s, 1e-9),
      static_cast<double>(s.medium_busy_ns) / (sc.sim_s * 1e9), static_cast<unsigned long long>(s.lost_per),
      static_cast<unsigned long long>(s.lost_range), static_cast<unsigned long long>(s.lost_queue));
  std::fflush(stdout);
  return deliveries > 0 ? 0 : 1;
}

int RunRadioBench(const swarmbox::bench::Args& args) {
  const std::string name = args.Get("profile", "wifi_5ghz_mesh");
  const std::string path = name.find('/') != std::string::npos ? name : std::string(SWARMBOX_RADIOS_DIR) + "/" + name + ".yaml";
  auto profile = LoadRadioProfile(path);
  if (!profile) {
    std::fprintf(stderr, "radio bench: %s\n", profile.error().ToString().c_str());
    return 2;
  }
  Scenario sc;
  sc.sim_s = args.GetDouble("sim-s", args.quick ? 2.0 : 60.0);
  sc.area_m = args.GetDouble("area-m", 200.0);
  sc.frame_bytes = static_cast<std::uint32_t>(args.GetInt("frame-bytes", 120));
  std::vector<std::size_t> sizes{10, 50, 100};
  if (const long n = args.GetInt("drones", 0); n > 0) sizes = {static_cast<std::size_t>(n)};
  int worst = 0;
  for (std::size_t n : sizes) {
    sc.drones = n;
    if (int rc = RunScenario(*profile, sc); rc != 0) worst = rc;
  }
  return worst;
}

}  // namespace

SWARMBOX_BENCH_SUITE(radio, "simulated radio channel: deliveries/s and CPU per delivery, 10/50/100 drones at 10 Hz",
                     RunRadioBench);
