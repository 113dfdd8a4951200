// `swarmbox-bench stereo [--quick] [--seed=N]`: the OAK-D Pro's depth (issue #23) on three
// surfaces, projector on and off, over ranges 2-20 m: the physics library's stereo renderer draws
// the pair (trials/sensors/oak_d_pro_stereo.yaml), the agent's StereoMatcher (OpenCV StereoSGBM)
// matches it, and the depth is scored against the renderer's truth. One logfmt line per case:
//
//   suite=stereo surface=concrete_shade projector=on range_m=10 fill_rate=0.83
//     depth_err_median_m=0.12 depth_err_p90_m=0.41 render_ms=210.3 sgbm_ms=35.1
//
// range_m: the camera's height above ground level (looking straight down; rubble heaps rise up to
// ~1.2 m towards it). fill_rate: share of the pixels the right view can match (right of the left
// band of num_disparities columns) that have a depth; errors |depth - truth| over those with depth,
// depth_bias_median_m the median of depth - truth (a matcher that locks on whole pixels of
// disparity reads far surfaces too near or too far).
// render_ms: both views; sgbm_ms: the matcher on the pair (one thread each, this machine).
// pair_fnv: a 64-bit FNV-1a hash of the left, right and truth-depth images' bytes, so that a
// change to the renderer that must not change its output (a faster ray march) can be checked by
// diffing two runs' lines without the timing fields.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

#include "bench.hpp"
#include "stereo_capture.hpp"
#include "swarmbox/depth/stereo_matcher.hpp"
#include "swarmbox/physics/stereo_renderer.hpp"
#include "swarmbox/physics/world.hpp"
#include "swarmbox/physics/world_scene.hpp"

#include <opencv2/core/utility.hpp>

namespace {

using swarmbox::physics::StereoSurface;
using Clock = std::chrono::steady_clock;  // benchmark timing only

// FNV-1a over the bytes of `images` (each continuous, as the renderer allocates them).
std::uint64_t PairHash(std::initializer_list<const cv::Mat*> images) {
  constexpr std::uint64_t kFnvOffset = 14695981039346656037ULL, kFnvPrime = 1099511628211ULL;
  std::uint64_t h = kFnvOffset;
  for (const cv::Mat* m : images) {
    const cv::Mat c = m->isContinuous() ? *m : m->clone();
    const auto* p = c.ptr<unsigned char>(0);
    for (std::size_t i = 0, n = c.total() * c.elemSize(); i < n; ++i) h = (h ^ p[i]) * kFnvPrime;
  }
  return h;
}

double Quantile(std::vector<double>* v, double q) {
  if (v->empty()) return 0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v->size() - 1));
  std::nth_element(v->begin(), v->begin() + static_cast<std::ptrdiff_t>(k), v->end());
  return (*v)[k];
}

int RunStereoBench(const swarmbox::bench::Args& args) {
  cv::setNumThreads(1);                     // ms per frame on one core
  const auto seed = static_cast<std::uint64_t>(args.GetInt("seed", 11));
  const std::vector<double> ranges = args.quick ? std::vector<double>{2, 10}
                                                : std::vector<double>{2, 4, 6, 8, 10, 12, 15, 20};
  const StereoSurface surfaces[] = {StereoSurface::kRubble, StereoSurface::kConcreteShade, StereoSurface::kSandSun};
  swarmbox::physics::StereoSpec spec;  // the defaults are trials/sensors/oak_d_pro_stereo.yaml's
  spec.enabled = true;
  swarmbox::depth::StereoMatcher matcher({.num_disparities = spec.num_disparities});
  for (StereoSurface surface : surfaces) {
    // Large enough for the footprint at 20 m (2 * 20 * tan(36 deg) = 29 m across).
    const swarmbox::physics::StereoScene scene = swarmbox::physics::MakeSurfaceScene(surface, 48.0, seed);
    swarmbox::physics::StereoRenderer renderer(&scene);
    for (bool projector : {true, false}) {
      spec.projector.enabled = projector;
      for (double range : ranges) {
        swarmbox::physics::Pose body;
        body.position_m = {0, 0, range - spec.offset_m.z};
        swarmbox::physics::StereoFrame frame;
        const auto t0 = Clock::now();
        renderer.Render(body, spec, seed, &frame);
        const auto t1 = Clock::now();
        cv::Mat depth;
        matcher.Compute(frame.left, frame.right, frame.focal_px, frame.baseline_m, &depth);
        const auto t2 = Clock::now();
        std::vector<double> err, signed_err;
        int n = 0;
        for (int v = 0; v < depth.rows; ++v) {
          const auto* z = depth.ptr<float>(v);
          const auto* truth = frame.depth_truth_m.ptr<float>(v);
          for (int u = spec.num_disparities; u < depth.cols; ++u) {
            if (!(truth[u] > 0)) continue;
            ++n;
            if (z[u] > 0) {
              err.push_back(std::abs(static_cast<double>(z[u]) - truth[u]));
              signed_err.push_back(static_cast<double>(z[u]) - truth[u]);
            }
          }
        }
        const double fill = n > 0 ? static_cast<double>(err.size()) / n : 0.0;
        const double med = Quantile(&err, 0.5), p90 = Quantile(&err, 0.9), bias = Quantile(&signed_err, 0.5);
        std::printf(
            "suite=stereo surface=%s projector=%s range_m=%g fill_rate=%.3f depth_err_median_m=%.3f "
            "depth_err_p90_m=%.3f depth_bias_median_m=%.3f pair_fnv=%016llx render_ms=%.1f sgbm_ms=%.1f\n",
            swarmbox::physics::StereoSurfaceName(surface), projector ? "on" : "off", range, fill, med, p90, bias,
            static_cast<unsigned long long>(PairHash({&frame.left, &frame.right, &frame.depth_truth_m})),
            std::chrono::duration<double, std::milli>(t1 - t0).count(),
            std::chrono::duration<double, std::milli>(t2 - t1).count());
        std::fflush(stdout);
      }
    }
  }
  return 0;
}

// ---- stereo_world: what a trial pays for a stereo drone -----------------------------------------
//
// `swarmbox-bench stereo_world [--quick] [--world=rubble_block] [--seed=N]`: the physics server's
// stereo path (issue #23) over a trial world (trials/worlds/<world>.yaml), looking down on its
// slab_1 corner (x = 5, y = 12). One line per height:
//
//   suite=stereo_world world=rubble_block height_m=10 half_m=12.9 cells=265225 scene_ms=9.1
//     render_ms=80.2 pack_ms=0.3 pair_fnv=0123456789abcdef
//
// scene_ms: MakeWorldScene's patch (PatchHalfSizeM); render_ms: StereoRenderer, both views (the
// fastest of kTimedRenders); pack_ms: PackStereoPair (the bus layout); pair_fnv: as the stereo
// suite's. Then one line for the trial step: one x500_depth held
// (pinned) 10 m up there, `steps` World::Step()s alone and the same with StereoCapture's pairs on
// their 5 Hz schedule, as the server runs them (no bus: publishing is BENCHMARKS.md "bus"):
//
//   suite=stereo_world scenario=trial_step steps=500 pairs=10 step_ms=0.05 step_with_pairs_ms=1.9
//     pair_ms=90.1 cpu_s_per_sim_s=0.47
//
// scenario=trial_step_bodies: the same with bodies in the pair (StereoScene::boxes): an
// x8_heavy_depth with its stretcher hanging in its view and 99 x500s pinned around it 4 m lower
// (a few in its view, the rest culled); what drawing bodies costs is its pair_ms less trial_step's.

double MsSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

constexpr double kLookX_m = 5.0, kLookY_m = 12.0;  // rubble_block's slab_1, walls and a victim in view
constexpr int kTimedRenders = 3;  // render_ms is the fastest of these (the host is shared)

// One line of pair costs with the camera `height_m` straight above (look_x_m, look_y_m); `place`
// (if not empty) names the look point.
void PrintPairCosts(const swarmbox::physics::WorldConfig& world, const std::string& name, const std::string& place,
                    double look_x_m, double look_y_m, double height_m, std::uint64_t seed) {
  namespace ph = swarmbox::physics;
  ph::StereoSpec spec;  // trials/sensors/oak_d_pro_stereo.yaml's figures
  spec.enabled = true;
  const double half_m = ph::StereoCapture::PatchHalfSizeM(height_m, spec.hfov_rad);
  auto t0 = Clock::now();
  const ph::StereoScene scene = ph::MakeWorldScene(world, look_x_m, look_y_m, half_m, world.ground_texture_seed);
  const double scene_ms = MsSince(t0);
  ph::StereoRenderer renderer(&scene);
  ph::Pose body;
  body.position_m = {look_x_m, look_y_m, height_m};
  ph::StereoFrame frame;
  renderer.Render(body, spec, seed, &frame);  // the dot pattern is drawn once per renderer: not timed
  double render_ms = 0;
  for (int i = 0; i < kTimedRenders; ++i) {
    t0 = Clock::now();
    renderer.Render(body, spec, seed + 1, &frame);
    render_ms = i == 0 ? MsSince(t0) : std::min(render_ms, MsSince(t0));
  }
  swarmbox::bus::CameraImage pair;
  t0 = Clock::now();
  ph::PackStereoPair(frame, "bench", 0, 0, &pair);
  const double pack_ms = MsSince(t0);
  const std::string place_field = place.empty() ? "" : " place=" + place;
  std::printf("suite=%s world=%s%s height_m=%g half_m=%.1f cells=%d scene_ms=%.1f render_ms=%.1f pack_ms=%.2f "
              "pair_fnv=%016llx\n",
              place.empty() ? "stereo_world" : "stereo_tall", name.c_str(), place_field.c_str(), height_m, half_m,
              scene.height_m.rows * scene.height_m.cols, scene_ms, render_ms, pack_ms,
              static_cast<unsigned long long>(PairHash({&frame.left, &frame.right, &frame.depth_truth_m})));
  std::fflush(stdout);
}

// The trial step's drones: one stereo drone pinned `height_m` over the look point (x500_depth;
// with `bodies`, x8_heavy_depth with its stretcher hanging in its view) and, with `bodies`,
// kOtherDrones x500s pinned on a kGridSpacing_m grid 4 m under it around the look point (a few in
// its view, the rest beyond the patch: culled).
constexpr int kOtherDrones = 99;
constexpr double kGridSpacing_m = 6.0;
bool AddTrialDrones(swarmbox::physics::World& world, double height_m, bool bodies) {
  namespace ph = swarmbox::physics;
  const std::string dir = std::string(SWARMBOX_TRIALS_DIR) + "/airframes/";
  auto stereo = ph::LoadAirframe(dir + (bodies ? "x8_heavy_depth.yaml" : "x500_depth.yaml"));
  auto x500 = ph::LoadAirframe(dir + "x500.yaml");
  if (!stereo || !x500) return false;
  ph::DroneSpawn spawn;
  spawn.name = "scout_1";
  spawn.airframe = *stereo;
  spawn.position_m = {kLookX_m, kLookY_m, height_m};
  if (bodies) spawn.payload = "stretcher", spawn.payload_attached = true;
  if (!world.AddDrone(spawn)) return false;
  spawn.airframe = *x500;
  spawn.payload = "", spawn.payload_attached = false;
  for (int i = 0; bodies && i < kOtherDrones; ++i) {
    spawn.name = "d" + std::to_string(i);
    spawn.position_m = {kLookX_m + kGridSpacing_m * (i % 10 - 4.5), kLookY_m + kGridSpacing_m * (i / 10 - 4.5),
                        height_m - 4};
    if (!world.AddDrone(spawn)) return false;
  }
  for (std::size_t i = 0; i < world.drone_count(); ++i) world.SetPinned(i, true);
  return true;
}

// Mean ms of `steps` World::Step()s of a world with AddTrialDrones' drones, with (`pairs`) or
// without StereoCapture's pairs of drone 0 at their due steps.
double StepMs(const swarmbox::physics::WorldConfig& config, double height_m, int steps, bool pairs, bool bodies,
              int* rendered) {
  namespace ph = swarmbox::physics;
  auto world = ph::World::Create(config, {.seed = 1});
  if (!world || !AddTrialDrones(**world, height_m, bodies)) return -1;
  ph::StereoCapture capture(**world);
  swarmbox::bus::CameraImage pair;
  *rendered = 0;
  const auto t0 = Clock::now();
  for (int k = 0; k < steps; ++k) {
    const std::uint64_t step = (*world)->step_count();
    if (pairs && capture.Due(0, step)) {
      capture.Capture(**world, 0, step, &pair);
      ++*rendered;
    }
    (*world)->Step();
  }
  return MsSince(t0) / steps;
}

// One trial_step line: the step's cost without and with the pairs, and a pair's share.
bool PrintTrialStep(const swarmbox::physics::WorldConfig& config, const std::string& name, int steps, bool bodies) {
  constexpr double kTrialHeight_m = 10.0;
  int rendered = 0;
  const double plain_ms = StepMs(config, kTrialHeight_m, steps, false, bodies, &rendered);
  const double with_ms = StepMs(config, kTrialHeight_m, steps, true, bodies, &rendered);
  if (plain_ms < 0 || with_ms < 0 || rendered == 0) return false;
  const double pair_ms = (with_ms - plain_ms) * steps / rendered;
  constexpr double kStepsPerSimS = 250.0;  // the server's default control rate
  std::printf("suite=stereo_world scenario=%s world=%s height_m=%g steps=%d pairs=%d step_ms=%.3f "
              "step_with_pairs_ms=%.3f pair_ms=%.1f cpu_s_per_sim_s=%.2f\n",
              bodies ? "trial_step_bodies" : "trial_step", name.c_str(), kTrialHeight_m, steps, rendered, plain_ms,
              with_ms, pair_ms, with_ms * kStepsPerSimS / 1000.0);
  std::fflush(stdout);
  return true;
}

int RunStereoWorldBench(const swarmbox::bench::Args& args) {
  cv::setNumThreads(1);
  const std::string name = args.Get("world", "rubble_block");
  const auto seed = static_cast<std::uint64_t>(args.GetInt("seed", 11));
  auto world = swarmbox::physics::LoadWorld(std::string(SWARMBOX_TRIALS_DIR) + "/worlds/" + name + ".yaml");
  if (!world) {
    std::fprintf(stderr, "stereo_world: %s\n", world.error().ToString().c_str());
    return 1;
  }
  const std::vector<double> heights = args.quick ? std::vector<double>{10} : std::vector<double>{3, 6, 10, 15, 20};
  for (double h : heights) PrintPairCosts(*world, name, "", kLookX_m, kLookY_m, h, seed);
  const int steps = args.quick ? 100 : 500;
  if (!PrintTrialStep(*world, name, steps, false) || !PrintTrialStep(*world, name, steps, true)) {
    std::fprintf(stderr, "stereo_world: could not set up the trial step\n");
    return 1;
  }
  return 0;
}

// ---- stereo_tall: the pair over tall woodland ---------------------------------------------------
//
// `swarmbox-bench stereo_tall [--quick] [--seed=N]`: as stereo_world's pair lines, over
// trials/worlds/tree_lines.yaml (two strips of 26 m woodland, 12 m wide, along x = 20 and
// y = 20) where the scouts search at 30 m, 4 m over the crowns: a ray starts at the crowns' level,
// so over the meadow it crosses 26 m of empty space before the ground. Places: `meadow` (0, 0),
// 14 m from both strips' edges, both in view from 30 m; `crowns` (20, 0), over the north-south
// strip. Heights 30 m (4 m over the crowns) and, over the meadow, 10 m (below them: the march
// starts at the near clip); over the crowns 56 m (30 m over them). --quick: 30 m only.
//
//   suite=stereo_tall world=tree_lines place=meadow height_m=30 half_m=30.0 cells=1442401
//     scene_ms=150.2 render_ms=1010.3 pack_ms=0.10 pair_fnv=0123456789abcdef

int RunStereoTallBench(const swarmbox::bench::Args& args) {
  cv::setNumThreads(1);
  const auto seed = static_cast<std::uint64_t>(args.GetInt("seed", 11));
  auto world = swarmbox::physics::LoadWorld(std::string(SWARMBOX_TRIALS_DIR) + "/worlds/tree_lines.yaml");
  if (!world) {
    std::fprintf(stderr, "stereo_tall: %s\n", world.error().ToString().c_str());
    return 1;
  }
  struct Look {
    const char* place;
    double x_m, y_m, height_m;
    bool quick;
  };
  constexpr Look kLooks[] = {{"meadow", 0, 0, 30, true},
                             {"meadow", 0, 0, 10, false},
                             {"crowns", 20, 0, 30, true},
                             {"crowns", 20, 0, 56, false}};
  for (const Look& look : kLooks) {
    if (args.quick && !look.quick) continue;
    PrintPairCosts(*world, "tree_lines", look.place, look.x_m, look.y_m, look.height_m, seed);
  }
  return 0;
}

}  // namespace

SWARMBOX_BENCH_SUITE(stereo_tall, "The stereo pair over 26 m woodland (tree_lines): ms per pair beside and over the crowns",
                     RunStereoTallBench);

SWARMBOX_BENCH_SUITE(stereo_world, "A trial's stereo pairs: ms per pair over a world scene (patch, render, pack) and per step",
                     RunStereoWorldBench);

SWARMBOX_BENCH_SUITE(stereo, "OAK-D Pro stereo depth: fill and error per surface, projector, range; ms per pair",
                     RunStereoBench);
