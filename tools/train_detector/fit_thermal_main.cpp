// swarmbox-fit-thermal: fits the thermal evidence the agent adds to the colour detector's
// candidates (agent/swarm thermal_evidence.hpp) on rendered training worlds, and writes it with its
// provenance (the `fit-thermal` target: agent/swarm/models/thermal_evidence.yaml).
//
//   swarmbox-fit-thermal --out FILE [--seed N (9001)] [--worlds N (40)] [--radius-m R (0.7)]
//
// Worlds: rubble fields as trials/sar_rubble.yaml generates them (160 x 160 m, 4 people, 30
// obstacles, 25 distractors, their own time of day and overcast), world seeds drawn from --seed;
// the seeds of `swarmbox-bench thermal` (1-10) are refused. Each person at least half visible is
// looked at straight down from 15-35 m (the close look's 18 m to above the search's 30 m), a few
// metres off centre, by the thermal camera (trials/sensors/boson_320_thermal.yaml, the physics
// server's ThermalRenderer); the point looked at is where they lie give or take the colour
// detector's geolocation error (0.4 m, one sigma). Negatives: every distractor (tarps, cones,
// backpacks, debris, rocks: what the colour detector fires on) and two ground points 3-12 m from
// each person, looked at likewise. Each point's contrast is ThermalContrastAt's (the agent's own
// code). The fit: a logistic regression of person-or-not on the contrast with the two classes
// weighted equally, so that its logit is the log-likelihood ratio the agent adds to the colour
// detector's logit: Llr(c) = slope (c - offset).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/airframe/thermal_spec.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/physics/thermal_renderer.hpp"
#include "swarmbox/physics/world_config.hpp"
#include "swarmbox/swarm/thermal_evidence.hpp"
#include "swarmbox/worlds/generator.hpp"

namespace {

using namespace swarmbox;

struct Sample {
  double contrast_k;
  bool person;
};

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

// Weighted logistic regression on one feature by Newton's method: returns (w1, w0) of
// logit = w1 c + w0, each class's weights summing to one half.
std::pair<double, double> FitLogistic(const std::vector<Sample>& samples) {
  double np = 0, nn = 0;
  for (const Sample& s : samples) (s.person ? np : nn) += 1;
  double w1 = 0, w0 = 0;
  for (int it = 0; it < 50; ++it) {
    double g1 = 0, g0 = 0, h11 = 0, h10 = 0, h00 = 0;
    for (const Sample& s : samples) {
      const double c = std::clamp(s.contrast_k, swarm::kMinContrastK, swarm::kMaxContrastK);
      const double wt = s.person ? 0.5 / np : 0.5 / nn;
      const double p = 1.0 / (1.0 + std::exp(-(w1 * c + w0)));
      const double y = s.person ? 1.0 : 0.0;
      g1 += wt * (p - y) * c, g0 += wt * (p - y);
      const double v = wt * p * (1 - p);
      h11 += v * c * c, h10 += v * c, h00 += v;
    }
    const double det = h11 * h00 - h10 * h10;
    if (!(det > 1e-12)) break;
    const double d1 = (h00 * g1 - h10 * g0) / det, d0 = (h11 * g0 - h10 * g1) / det;
    w1 -= d1, w0 -= d0;
    if (std::abs(d1) < 1e-9 && std::abs(d0) < 1e-9) break;
  }
  return {w1, w0};
}

double Auc(const std::vector<Sample>& samples) {
  std::vector<double> p, n;
  for (const Sample& s : samples) (s.person ? p : n).push_back(s.contrast_k);
  double wins = 0;
  for (double a : p) {
    for (double b : n) wins += a > b ? 1.0 : a == b ? 0.5 : 0.0;
  }
  return wins / (static_cast<double>(p.size()) * static_cast<double>(n.size()));
}

cv::Mat Kelvin(const physics::ThermalImage& img) {
  cv::Mat counts(img.height_px, img.width_px, CV_16U, const_cast<std::uint16_t*>(img.centikelvin.data())), k;
  counts.convertTo(k, CV_32F, 1.0 / physics::kThermalCountsPerK);
  return k;
}

int Usage() {
  std::fprintf(stderr, "usage: swarmbox-fit-thermal --out FILE [--seed N] [--worlds N] [--radius-m R]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out;
  std::uint64_t seed = 9001;
  int worlds_n = 40;
  double radius_m = 0.7;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) return Usage();
    const std::string v = argv[++i];
    if (a == "--out") {
      out = v;
    } else if (a == "--seed") {
      seed = std::strtoull(v.c_str(), nullptr, 10);
    } else if (a == "--worlds") {
      worlds_n = std::atoi(v.c_str());
    } else if (a == "--radius-m") {
      radius_m = std::atof(v.c_str());
    } else {
      return Usage();
    }
  }
  if (out.empty() || worlds_n < 1 || !(radius_m > 0.1 && radius_m < 3)) return Usage();
  if (seed >= 1 && seed <= 10) {
    std::fprintf(stderr,
                 "swarmbox-fit-thermal: seed %llu is one of swarmbox-bench thermal's (1-10): fit on others\n",
                 static_cast<unsigned long long>(seed));
    return 2;
  }
  auto doc = yaml::ParseFile(std::string(SWARMBOX_TRIALS_DIR) + "/sensors/boson_320_thermal.yaml");
  if (!doc) {
    std::fprintf(stderr, "swarmbox-fit-thermal: %s\n", doc.error().ToString().c_str());
    return 1;
  }
  auto spec = airframe::ParseThermalSpec(doc->Find("thermal"));
  if (!spec) {
    std::fprintf(stderr, "swarmbox-fit-thermal: %s\n", spec.error().ToString().c_str());
    return 1;
  }
  const worlds::GenerateSpec gen{.kind = worlds::WorldKind::kRubbleField,
                                 .size_m = {160, 160},
                                 .victims = 4,
                                 .obstacles = 30,
                                 .distractors = 25};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  std::normal_distribution<double> jitter(0.0, 0.4);
  std::vector<Sample> samples;
  physics::ThermalImage img;
  std::vector<physics::VisiblePerson> people;
  // Looks at world point (x, y) from a random height and offset; the contrast there, if defined
  // (and for a person, `id` at least half visible).
  auto look = [&](physics::ThermalRenderer& renderer, double x, double y,
                  const std::string& id) -> std::optional<double> {
    const double alt = 15 + 20 * unit(rng), yaw = unit(rng) * 2 * std::numbers::pi;
    const double cx = x + (unit(rng) - 0.5) * 0.3 * alt, cy = y + (unit(rng) - 0.5) * 0.3 * alt;
    renderer.Render(
        physics::Pose{physics::Vec3{cx, cy, alt}, physics::Quat{std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)}},
        *spec, rng(), &img, id.empty() ? nullptr : &people);
    if (!id.empty()) {
      const auto it = std::find_if(people.begin(), people.end(),
                                   [&](const physics::VisiblePerson& p) { return p.id == id; });
      if (it == people.end() || it->visible_fraction < 0.5) return std::nullopt;
    }
    const physics::Pose& pose = img.camera_pose;
    const swarm::ThermalView view{
        Kelvin(img),
        {img.intrinsics.fx_px, img.intrinsics.fy_px, img.intrinsics.cx_px, img.intrinsics.cy_px},
        {Eigen::Vector3d(pose.position_m.x, pose.position_m.y, pose.position_m.z),
         Eigen::Quaterniond(pose.attitude.w, pose.attitude.x, pose.attitude.y, pose.attitude.z)}};
    return swarm::ThermalContrastAt(view, Eigen::Vector3d(x + jitter(rng), y + jitter(rng), 0.0), radius_m);
  };
  for (int w = 0; w < worlds_n; ++w) {
    const std::uint64_t world_seed = rng() % 1'000'000'000ULL;
    auto text = worlds::GenerateWorld(gen, world_seed);
    if (!text) {
      std::fprintf(stderr, "swarmbox-fit-thermal: %s\n", text.error().ToString().c_str());
      return 1;
    }
    auto root = yaml::Parse(*text, "generated world");
    if (!root) return 1;
    auto world = physics::ParseWorld(*root, "generated world " + std::to_string(world_seed));
    if (!world) {
      std::fprintf(stderr, "swarmbox-fit-thermal: %s\n", world.error().ToString().c_str());
      return 1;
    }
    physics::ThermalRenderer renderer(*world);
    for (const physics::Victim& v : world->victims) {
      if (auto c = look(renderer, v.x_m, v.y_m, v.id)) samples.push_back({*c, true});
      for (int k = 0; k < 2; ++k) {
        const double r = 3 + 9 * unit(rng), a = unit(rng) * 2 * std::numbers::pi;
        if (auto c = look(renderer, v.x_m + r * std::cos(a), v.y_m + r * std::sin(a), ""))
          samples.push_back({*c, false});
      }
    }
    for (const physics::Distractor& d : world->distractors) {
      if (auto c = look(renderer, d.x_m, d.y_m, "")) samples.push_back({*c, false});
    }
    std::fprintf(stderr, "swarmbox-fit-thermal: world %d/%d (seed %llu): %zu samples\n", w + 1, worlds_n,
                 static_cast<unsigned long long>(world_seed), samples.size());
  }
  std::vector<double> pc, nc;
  for (const Sample& s : samples) (s.person ? pc : nc).push_back(s.contrast_k);
  if (pc.size() < 10 || nc.size() < 10) {
    std::fprintf(stderr, "swarmbox-fit-thermal: too few samples (%zu people, %zu negatives)\n", pc.size(),
                 nc.size());
    return 1;
  }
  const auto [w1, w0] = FitLogistic(samples);
  if (!(w1 > 0)) {
    std::fprintf(
        stderr, "swarmbox-fit-thermal: the fit's slope is %g: warmer is not more likely a person here\n", w1);
    return 1;
  }
  const double offset = -w0 / w1;
  std::ofstream f(out);
  f << "# Thermal evidence for the colour detector's candidates (agent/swarm thermal_evidence.hpp):\n"
    << "# Llr(c) = slope_per_k (c - offset_k) added to the detector's logit, c the contrast within\n"
    << "# radius_m of the candidate's ground point. Written by swarmbox-fit-thermal (the fit-thermal\n"
    << "# target; tools/train_detector/fit_thermal_main.cpp has the method): do not edit.\n"
    << "thermal_evidence:\n";
  char line[512];
  std::snprintf(line, sizeof line, "  slope_per_k: %.6f\n  offset_k: %.4f\n  radius_m: %.3f\n", w1, offset,
                radius_m);
  f << line;
  std::snprintf(
      line, sizeof line,
      "  fit: {seed: %llu, worlds: %d, people: %zu, negatives: %zu, auc: %.4f, person_contrast_p10_k: %.2f,\n"
      "        person_contrast_p50_k: %.2f, negative_contrast_p50_k: %.2f, negative_contrast_p90_k: %.2f}\n",
      static_cast<unsigned long long>(seed), worlds_n, pc.size(), nc.size(), Auc(samples), Quantile(pc, 0.1),
      Quantile(pc, 0.5), Quantile(nc, 0.5), Quantile(nc, 0.9));
  f << line;
  if (!f) {
    std::fprintf(stderr, "swarmbox-fit-thermal: cannot write %s\n", out.c_str());
    return 1;
  }
  std::printf(
      "fit=thermal seed=%llu worlds=%d people=%zu negatives=%zu slope_per_k=%.4f offset_k=%.3f auc=%.4f\n",
      static_cast<unsigned long long>(seed), worlds_n, pc.size(), nc.size(), w1, offset, Auc(samples));
  return 0;
}
