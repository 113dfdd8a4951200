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
#include "swarmbox/depth/stereo_matcher.hpp"
#include "swarmbox/physics/stereo_renderer.hpp"

#include <opencv2/core/utility.hpp>

namespace {

using swarmbox::physics::StereoSurface;

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
  using Clock = std::chrono::steady_clock;  // benchmark timing only
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

}  // namespace

SWARMBOX_BENCH_SUITE(stereo, "OAK-D Pro stereo depth: fill and error per surface, projector, range; ms per pair",
                     RunStereoBench);
