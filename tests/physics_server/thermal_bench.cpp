// swarmbox-bench thermal: what the thermal camera (trials/sensors/boson_320_thermal.yaml,
// ThermalRenderer) tells apart on the mission's generated rubble fields, and what a frame costs.
//   suite=thermal altitude_m=18 light=sun people=... lookalikes=... person_contrast_p10_k=...
//     person_contrast_p50_k=... lookalike_contrast_p50_k=... lookalike_contrast_p90_k=...
//     auc_people_vs_distractors=... auc_people_vs_lookalikes=... auc_cnn_people_vs_lookalikes=...
//     ms_per_frame=... ms_per_classification=...
// Worlds: --worlds (20) rubble fields as trials/sar_rubble.yaml generates them (160 x 160 m, 4
// people, 30 obstacles, 25 distractors; seeds from --seed, 1), with their own time of day and
// overcast; light=sun: 9-15 h under less than half cloud, light=dim the rest. Each person and
// each distractor is looked at from 18 m (the close look) and 30 m (the search), straight down, a
// few metres off centre, at a random yaw. Its contrast: the 98th percentile of the temperatures
// in its box (a person's: the renderer's truth box, at least half visible; a distractor's: its
// size around its projected centre) minus the median of a ring around the box [K].
// Lookalikes: backpacks and debris, what the RGB detector's false victims were on rubble20
// (BENCHMARKS.md, "Where the false victims are"). AUC: the share of (person, thing) pairs in
// which the person has the larger contrast. A frame's cost is the process's CPU time.
// The agent's thermal classifier (agent/swarm thermal_evidence.hpp, the shipped network) scores the
// patch at each person's and thing's ground point in the same frames: auc_cnn_people_vs_lookalikes
// and ms_per_classification (CPU time of one ThermalClassifier::Logit, the patch's resampling
// included).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench.hpp"
#include "perception_scenes.hpp"
#include "swarmbox/airframe/thermal_spec.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/physics/thermal_renderer.hpp"
#include "swarmbox/physics/world_config.hpp"
#include "swarmbox/swarm/thermal_evidence.hpp"
#include "swarmbox/worlds/generator.hpp"

namespace {

using namespace swarmbox;
using namespace swarmbox::physics;

double CpuS() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// The 98th percentile inside `box` minus the median of the ring `ring_px` wide around it [K];
// NaN when the box or the ring leaves the image.
double Contrast(const ThermalImage& img, const cv::Rect& box, int ring_px) {
  const cv::Rect frame(0, 0, img.width_px, img.height_px);
  const cv::Rect outer(box.x - ring_px, box.y - ring_px, box.width + 2 * ring_px, box.height + 2 * ring_px);
  if ((outer & frame) != outer || box.area() < 4) return std::nan("");
  std::vector<std::uint16_t> in, ring;
  for (int y = outer.y; y < outer.y + outer.height; ++y) {
    for (int x = outer.x; x < outer.x + outer.width; ++x) {
      const std::uint16_t v =
          img.centikelvin[static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width_px) +
                          static_cast<std::size_t>(x)];
      (box.contains(cv::Point(x, y)) ? in : ring).push_back(v);
    }
  }
  auto quantile = [](std::vector<std::uint16_t>& v, double q) {
    const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return static_cast<double>(v[static_cast<std::size_t>(k)]);
  };
  return (quantile(in, 0.98) - quantile(ring, 0.5)) / kThermalCountsPerK;
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

// P(person > thing) over all pairs, ties counting half.
double Auc(const std::vector<double>& people, const std::vector<double>& things) {
  if (people.empty() || things.empty()) return std::nan("");
  double wins = 0;
  for (double p : people) {
    for (double t : things) wins += p > t ? 1.0 : p == t ? 0.5 : 0.0;
  }
  return wins / (static_cast<double>(people.size()) * static_cast<double>(things.size()));
}

struct Tally {
  std::vector<double> people, lookalikes, distractors;
  std::vector<double> people_cnn, lookalikes_cnn;  // the classifier's logits
  double render_s = 0, cnn_s = 0;
  int frames = 0, classified = 0;
};

// The classifier's logit on the patch at ground point (x, y) of `view` into `out`, its cost into
// the tally; nothing when the patch leaves the frame.
void Classify(swarm::ThermalClassifier& classifier, const swarm::ThermalView& view, double x, double y,
              Tally* t, std::vector<double>* out) {
  const double t0 = CpuS();
  cv::Mat patch;
  if (!swarm::ThermalPatchAt(view, Eigen::Vector3d(x, y, 0), &patch)) return;
  out->push_back(classifier.Logit(patch));
  t->cnn_s += CpuS() - t0;
  ++t->classified;
}

Pose NadirPose(double x, double y, double alt, double yaw) {
  return Pose{Vec3{x, y, alt}, Quat{std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)}};
}

int RunThermalBench(const bench::Args& args) {
  auto doc = yaml::ParseFile(std::string(SWARMBOX_TRIALS_DIR) + "/sensors/boson_320_thermal.yaml");
  if (!doc) {
    std::fprintf(stderr, "thermal bench: %s\n", doc.error().ToString().c_str());
    return 1;
  }
  auto spec = airframe::ParseThermalSpec(doc->Find("thermal"));
  if (!spec) {
    std::fprintf(stderr, "thermal bench: %s\n", spec.error().ToString().c_str());
    return 1;
  }
  const swarm::ThermalEvidence& evidence = swarm::ShippedThermalEvidence();
  if (evidence.cnn_onnx == nullptr) {
    std::fprintf(stderr, "thermal bench: the shipped thermal evidence has no classifier\n");
    return 1;
  }
  Result<std::unique_ptr<swarm::ThermalClassifier>> classifier =
      swarm::ThermalClassifier::FromOnnx(*evidence.cnn_onnx);
  if (!classifier) {
    std::fprintf(stderr, "thermal bench: %s\n", classifier.error().ToString().c_str());
    return 1;
  }
  const int worlds_n = static_cast<int>(args.GetInt("worlds", args.quick ? 2 : 20));
  const auto seed = static_cast<std::uint64_t>(args.GetInt("seed", 1));
  const std::string png = args.Get("png", "");
  const double altitudes[] = {18.0, 30.0};
  Tally tally[2][2];  // [altitude][sun]
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  double build_s = 0;
  const worlds::GenerateSpec gen{.kind = worlds::WorldKind::kRubbleField,
                                 .size_m = {160, 160},
                                 .victims = 4,
                                 .obstacles = 30,
                                 .distractors = 25};
  for (int w = 0; w < worlds_n; ++w) {
    const std::uint64_t world_seed = rng() % 1'000'000'000ULL;
    auto text = worlds::GenerateWorld(gen, world_seed);
    if (!text) {
      std::fprintf(stderr, "thermal bench: %s\n", text.error().ToString().c_str());
      return 1;
    }
    auto root = yaml::Parse(*text, "generated world");
    if (!root) return 1;
    auto world = ParseWorld(*root, "generated world " + std::to_string(world_seed));
    if (!world) {
      std::fprintf(stderr, "thermal bench: %s\n", world.error().ToString().c_str());
      return 1;
    }
    const Lighting light = world->lighting.value_or(Lighting{});
    const int sun = (light.overcast < 0.5 && light.time_of_day_h >= 9 && light.time_of_day_h <= 15) ? 1 : 0;
    const double b0 = CpuS();
    ThermalRenderer renderer(*world);
    build_s += CpuS() - b0;
    ThermalImage img;
    std::vector<VisiblePerson> people;
    for (int a = 0; a < 2; ++a) {
      const double alt = altitudes[a];
      Tally& t = tally[a][sun];
      const double f = spec->FocalPx();
      for (const Victim& v : world->victims) {
        const Pose pose =
            NadirPose(v.x_m + (unit(rng) - 0.5) * 0.3 * alt, v.y_m + (unit(rng) - 0.5) * 0.3 * alt, alt,
                      unit(rng) * 2 * std::numbers::pi);
        const double t0 = CpuS();
        renderer.Render(pose, *spec, rng(), &img, &people);
        t.render_s += CpuS() - t0;
        ++t.frames;
        for (const VisiblePerson& p : people) {
          if (p.id != v.id || p.visible_fraction < 0.5) continue;
          const double c = Contrast(img, p.box_px, std::max(6, p.box_px.width / 2));
          if (!std::isnan(c)) t.people.push_back(c);
          Classify(**classifier, perception_scenes::ThermalViewOf(img), v.x_m, v.y_m, &t, &t.people_cnn);
        }
        if (!png.empty() && w < 2) {
          cv::Mat k(img.height_px, img.width_px, CV_16U, img.centikelvin.data()), view;
          cv::normalize(k, view, 0, 255, cv::NORM_MINMAX, CV_8U);
          cv::imwrite(png + "/thermal_w" + std::to_string(w) + "_" + v.id + "_" +
                          std::to_string(static_cast<int>(alt)) + "m.png",
                      view);
        }
      }
      for (const Distractor& d : world->distractors) {
        const double dx = (unit(rng) - 0.5) * 0.3 * alt, dy = (unit(rng) - 0.5) * 0.3 * alt,
                     yaw = unit(rng) * 2 * std::numbers::pi;
        const double t0 = CpuS();
        renderer.Render(NadirPose(d.x_m + dx, d.y_m + dy, alt, yaw), *spec, rng(), &img, nullptr);
        t.render_s += CpuS() - t0;
        ++t.frames;
        // The thing's centre in the image of a level camera: optical x = -body y, optical y =
        // -body x, the body turned by yaw.
        const double ex = -dx, ey = -dy;  // thing - camera, world
        const double bx = std::cos(yaw) * ex + std::sin(yaw) * ey,
                     by = -std::sin(yaw) * ex + std::cos(yaw) * ey;
        const double u = img.intrinsics.cx_px - f * by / alt, vpx = img.intrinsics.cy_px - f * bx / alt;
        const int half = std::max(2, static_cast<int>(std::lround(0.6 * d.size_m * f / alt)));
        const cv::Rect box(static_cast<int>(std::lround(u)) - half, static_cast<int>(std::lround(vpx)) - half,
                           2 * half, 2 * half);
        const double c = Contrast(img, box, std::max(6, half));
        if (std::isnan(c)) continue;
        t.distractors.push_back(c);
        if (d.kind == DistractorKind::kBackpack || d.kind == DistractorKind::kDebris) {
          t.lookalikes.push_back(c);
          Classify(**classifier, perception_scenes::ThermalViewOf(img), d.x_m, d.y_m, &t, &t.lookalikes_cnn);
        }
      }
    }
  }
  for (int a = 0; a < 2; ++a) {
    for (int s = 0; s < 2; ++s) {
      const Tally& t = tally[a][s];
      if (t.frames == 0) continue;
      std::printf(
          "suite=thermal altitude_m=%.0f light=%s worlds=%d people=%zu lookalikes=%zu distractors=%zu "
          "person_contrast_p10_k=%.2f person_contrast_p50_k=%.2f lookalike_contrast_p50_k=%.2f "
          "lookalike_contrast_p90_k=%.2f auc_people_vs_distractors=%.3f auc_people_vs_lookalikes=%.3f "
          "auc_cnn_people_vs_lookalikes=%.3f ms_per_frame=%.2f ms_per_classification=%.2f build_ms=%.0f\n",
          altitudes[a], s ? "sun" : "dim", worlds_n, t.people.size(), t.lookalikes.size(),
          t.distractors.size(), Quantile(t.people, 0.1), Quantile(t.people, 0.5), Quantile(t.lookalikes, 0.5),
          Quantile(t.lookalikes, 0.9), Auc(t.people, t.distractors), Auc(t.people, t.lookalikes),
          Auc(t.people_cnn, t.lookalikes_cnn), t.render_s / t.frames * 1e3,
          t.classified ? t.cnn_s / t.classified * 1e3 : std::nan(""), build_s / worlds_n * 1e3);
    }
  }
  std::fflush(stdout);
  return 0;
}

}  // namespace

SWARMBOX_BENCH_SUITE(thermal, "thermal camera: people against distractors by thermal contrast, ms per frame",
                     RunThermalBench);
