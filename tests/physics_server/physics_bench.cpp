// swarmbox-bench physics: N x500s held in hover by an in-process controller (no bus), cameras
// off and on. One logfmt line per scenario:
//   suite=physics scenario=hover drones=N camera=off sim_s=... wall_s=... rtf=... steps_per_s=...
// --quick: 1 s of simulated time per scenario instead of 10 s. --drones=N runs only N;
// --camera=off|on|both (default both); --sim-s=S simulated seconds per scenario.
// rtf = sim_s / wall_s; rtf_cpu = sim_s / process CPU time (the figure that stays meaningful on
// a loaded machine; equal to rtf on an idle core). Speed is printed, never asserted. The aim (issue): 100 drones at >= 10x real time, cameras off.
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bench.hpp"
#include "hover_controller.hpp"
#include "swarmbox/physics/world.hpp"

namespace {

using namespace swarmbox::physics;

std::string TrialsDir() { return SWARMBOX_TRIALS_DIR; }

int RunScenario(const WorldConfig& config, const Airframe& af, int drones, bool camera, double sim_s) {
  WorldOptions options;
  options.seed = 7;
  auto world = World::Create(config, options);
  if (!world) {
    std::fprintf(stderr, "physics bench: %s\n", world.error().ToString().c_str());
    return 1;
  }
  std::vector<testing::HoverController> controllers;
  controllers.reserve(static_cast<std::size_t>(drones));
  const double u0 = af.HoverRotorSpeed(0, config.gravity_m_s2) / af.motor.max_rot_velocity_rad_s;
  const int side = static_cast<int>(std::ceil(std::sqrt(drones)));
  for (int i = 0; i < drones; ++i) {
    DroneSpawn spawn;
    spawn.name = "d" + std::to_string(i);
    spawn.airframe = af;
    spawn.position_m = {(i % side) * 6.0 - side * 3.0, (i / side) * 6.0 - side * 3.0, 15.0};
    spawn.initial_throttle = u0;
    auto idx = (*world)->AddDrone(spawn);
    if (!idx) {
      std::fprintf(stderr, "physics bench: %s\n", idx.error().ToString().c_str());
      return 1;
    }
    controllers.emplace_back((*world)->airframe(*idx), spawn.position_m + Vec3{0, 0, af.base_height_m});
  }
  std::vector<double> u(af.rotors.size());
  CameraImage image;
  const auto steps = static_cast<long>(std::lround(sim_s * 1e9 / static_cast<double>(options.control_period_ns)));
  long frames = 0;
  double worst_alt_err = 0;
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  for (long k = 0; k < steps; ++k) {
    for (std::size_t i = 0; i < static_cast<std::size_t>(drones); ++i) {
      controllers[i].Update((*world)->Truth(i), &u);
      (void)(*world)->SetActuators(i, u);
      if (camera && (*world)->CameraDue(i)) {
        (*world)->RenderCamera(i, &image);
        ++frames;
      }
    }
    (*world)->Step();
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu_s = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  for (std::size_t i = 0; i < static_cast<std::size_t>(drones); ++i) {
    worst_alt_err = std::max(worst_alt_err, std::abs((*world)->Truth(i).position_m.z - (15.0 + af.base_height_m)));
  }
  std::printf(
      "suite=physics scenario=hover airframe=%s drones=%d camera=%s sim_s=%.1f wall_s=%.3f cpu_s=%.3f rtf=%.2f "
      "rtf_cpu=%.2f steps_per_s=%.0f drone_steps_per_s=%.0f frames=%ld max_alt_err_m=%.3f\n",
      af.name.c_str(), drones, camera ? "on" : "off", sim_s, wall_s, cpu_s, sim_s / wall_s, sim_s / cpu_s,
      static_cast<double>(steps) / wall_s,
      static_cast<double>(steps) * drones / wall_s, frames, worst_alt_err);
  std::fflush(stdout);
  return 0;
}

int RunPhysicsBench(const swarmbox::bench::Args& args) {
  auto config = LoadWorld(TrialsDir() + "/worlds/open_field.yaml");
  auto af = LoadAirframe(TrialsDir() + "/airframes/x500.yaml");
  if (!config || !af) {
    std::fprintf(stderr, "physics bench: %s\n", (!config ? config.error() : af.error()).ToString().c_str());
    return 1;
  }
  const double sim_s = args.GetDouble("sim-s", args.quick ? 1.0 : 10.0);
  std::vector<int> counts = {1, 10, 50, 100};
  if (const long only = args.GetInt("drones", 0); only > 0) counts = {static_cast<int>(only)};
  const std::string cam = args.Get("camera", "both");
  for (bool camera : {false, true}) {
    if ((cam == "off" && camera) || (cam == "on" && !camera)) continue;
    for (int n : counts) {
      if (int rc = RunScenario(*config, *af, n, camera, sim_s); rc != 0) return rc;
    }
  }
  return 0;
}

}  // namespace

SWARMBOX_BENCH_SUITE(physics, "ODE world: N x500s hovering under an in-process controller, cameras off/on",
                     RunPhysicsBench);
