#include "perception_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <string>

#include <opencv2/core.hpp>

#include "swarmbox/physics/airframe.hpp"
#include "swarmbox/physics/world.hpp"
#include "swarmbox/physics/world_config.hpp"

#ifndef SWARMBOX_TRIALS_DIR
#error "SWARMBOX_TRIALS_DIR must point at the project's trials/ folder"
#endif

namespace swarmbox::swarm::testing {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// Whether the segment a -> b passes through the (yawed) box.
bool SegmentHitsBox(const Vector3d& a, const Vector3d& b, const physics::ObstacleBox& box) {
  const double c = std::cos(box.yaw_rad), s = std::sin(box.yaw_rad);
  auto local = [&](const Vector3d& p) {
    const Vector3d d(p.x() - box.center_m.x, p.y() - box.center_m.y, p.z() - box.center_m.z);
    return Vector3d(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
  };
  const Vector3d p0 = local(a), p1 = local(b);
  const Vector3d half(box.size_m.x / 2, box.size_m.y / 2, box.size_m.z / 2);
  double t0 = 0, t1 = 1;
  for (int k = 0; k < 3; ++k) {
    const double d = p1[k] - p0[k];
    if (std::abs(d) < 1e-12) {
      if (p0[k] < -half[k] || p0[k] > half[k]) return false;
      continue;
    }
    double ta = (-half[k] - p0[k]) / d, tb = (half[k] - p0[k]) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

// Samples the figure as the renderer draws it (body ellipse 0.72 x 0.24 m centred 0.15 m toward
// the feet, head ellipse 0.13 x 0.11 m 0.7 m toward the head): kFull when every boundary sample
// projects inside the image (1 px margin) with a clear line of sight, kAbsent when none projects
// within 1 px of the image, kPartial otherwise.
Visibility Classify(const physics::Victim& v, const Scene& scene, const physics::WorldConfig& world) {
  const double ch = std::cos(v.heading_rad), sh = std::sin(v.heading_rad);
  const Vector2d h(ch, sh), perp(-sh, ch);
  const Vector2d c(v.x_m, v.y_m);
  std::vector<Vector2d> pts = {c};
  constexpr int kN = 20;
  for (int i = 0; i < kN; ++i) {
    const double t = 2 * std::numbers::pi * i / kN;
    pts.push_back(c - 0.15 * h + 0.72 * std::cos(t) * h + 0.24 * std::sin(t) * perp);
    pts.push_back(c + 0.70 * h + 0.13 * std::cos(t) * h + 0.11 * std::sin(t) * perp);
  }
  const double w = scene.image.width_px, hgt = scene.image.height_px;
  std::size_t inside = 0, near = 0, hidden = 0;
  for (const Vector2d& q : pts) {
    const Vector3d g(q.x(), q.y(), 0.0);
    const std::optional<Vector2d> px = ProjectToPixel(g, scene.intrinsics, scene.true_pose);
    if (!px) continue;
    if (px->x() >= 1 && px->y() >= 1 && px->x() <= w - 2 && px->y() <= hgt - 2) ++inside;
    if (px->x() >= -1 && px->y() >= -1 && px->x() <= w && px->y() <= hgt) ++near;
    for (const physics::ObstacleBox& b : world.obstacles) {
      if (SegmentHitsBox(scene.true_pose.position_m, g, b)) {
        ++hidden;
        break;
      }
    }
  }
  if (near == 0) return Visibility::kAbsent;
  if (inside == pts.size() && hidden == 0) return Visibility::kFull;
  return Visibility::kPartial;
}

physics::WorldConfig MakeWorld(std::mt19937_64& rng, int index) {
  physics::WorldConfig w;
  w.name = "perception_" + std::to_string(index);
  w.size_x_m = 200;
  w.size_y_m = 200;
  w.ground_texture_seed = rng();
  std::uniform_real_distribution<double> coord(-80, 80), unit(0, 1);
  while (w.victims.size() < 8) {
    physics::Victim v;
    v.id = "v" + std::to_string(w.victims.size() + 1);
    v.x_m = coord(rng);
    v.y_m = coord(rng);
    v.heading_rad = 2 * std::numbers::pi * unit(rng);
    bool ok = true;
    for (const physics::Victim& o : w.victims) ok = ok && std::hypot(o.x_m - v.x_m, o.y_m - v.y_m) > 6.0;
    if (ok) w.victims.push_back(v);
  }
  int attempts = 0;
  while (w.obstacles.size() < 12 && ++attempts < 1000) {
    physics::ObstacleBox b;
    b.id = "box" + std::to_string(w.obstacles.size());
    b.size_m = {2 + 8 * unit(rng), 2 + 8 * unit(rng), 1 + 7 * unit(rng)};
    b.center_m = {coord(rng), coord(rng), b.size_m.z / 2};
    b.yaw_rad = std::numbers::pi * unit(rng);
    const double reach = std::hypot(b.size_m.x, b.size_m.y) / 2 + 2.0 + 1.0;  // 2 m clear + figure
    bool ok = true;
    for (const physics::Victim& v : w.victims) ok = ok && std::hypot(v.x_m - b.center_m.x, v.y_m - b.center_m.y) > reach;
    if (ok) w.obstacles.push_back(b);
  }
  return w;
}

}  // namespace

Result<std::vector<Scene>> RenderScenes(const SceneSetParams& p) {
  Result<physics::Airframe> x500 = physics::LoadAirframe(std::string(SWARMBOX_TRIALS_DIR) + "/airframes/x500.yaml");
  if (!x500) return x500.error().Context("loading the x500 airframe for the camera");
  std::mt19937_64 rng(p.seed);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<Scene> scenes;
  scenes.reserve(static_cast<std::size_t>(p.scenes));
  int world_index = 0;
  while (static_cast<int>(scenes.size()) < p.scenes) {
    const physics::WorldConfig config = MakeWorld(rng, world_index);
    Result<std::unique_ptr<physics::World>> world = physics::World::Create(config, {.seed = rng()});
    if (!world) return world.error().Context("creating perception world");
    const int count = std::min(p.scenes_per_world, p.scenes - static_cast<int>(scenes.size()));
    for (int i = 0; i < count; ++i) {
      const double altitude = p.min_altitude_m + (p.max_altitude_m - p.min_altitude_m) * unit(rng);
      const double yaw = 2 * std::numbers::pi * unit(rng) - std::numbers::pi;
      const double half_w = altitude * std::tan(x500->camera.hfov_rad / 2);
      Vector2d centre;
      if (unit(rng) < p.near_victim_fraction) {
        const physics::Victim& v = config.victims[static_cast<std::size_t>(rng() % config.victims.size())];
        centre = Vector2d(v.x_m, v.y_m) + p.near_victim_offset * half_w * Vector2d(2 * unit(rng) - 1, 2 * unit(rng) - 1);
      } else {
        centre = Vector2d(160 * unit(rng) - 80, 160 * unit(rng) - 80);
      }
      physics::Airframe af = *x500;
      af.camera.noise_std = p.min_noise_std + (p.max_noise_std - p.min_noise_std) * unit(rng);
      physics::DroneSpawn spawn;
      spawn.name = "cam_" + std::to_string(i);
      spawn.airframe = af;
      spawn.position_m = {centre.x(), centre.y(), altitude - af.base_height_m};
      spawn.yaw_rad = yaw;
      Result<std::size_t> d = (*world)->AddDrone(spawn);
      if (!d) return d.error().Context("placing camera drone");
      Scene s;
      (*world)->RenderCamera(*d, &s.image);
      s.intrinsics = {s.image.intrinsics.fx_px, s.image.intrinsics.fy_px, s.image.intrinsics.cx_px,
                      s.image.intrinsics.cy_px};
      const physics::Pose& cp = s.image.camera_pose;
      s.true_pose.position_m = {cp.position_m.x, cp.position_m.y, cp.position_m.z};
      s.true_pose.rotation = Eigen::Quaterniond(cp.attitude.w, cp.attitude.x, cp.attitude.y, cp.attitude.z);
      s.altitude_m = cp.position_m.z;
      s.noise_std = af.camera.noise_std;
      for (const physics::Victim& v : config.victims) {
        s.victims.push_back({Vector2d(v.x_m, v.y_m), Classify(v, s, config)});
      }
      scenes.push_back(std::move(s));
    }
    ++world_index;
  }
  return scenes;
}

namespace {

Scene SceneFromImage(physics::CameraImage image, const physics::WorldConfig& config, double noise_std) {
  Scene s;
  s.image = std::move(image);
  s.intrinsics = {s.image.intrinsics.fx_px, s.image.intrinsics.fy_px, s.image.intrinsics.cx_px,
                  s.image.intrinsics.cy_px};
  const physics::Pose& cp = s.image.camera_pose;
  s.true_pose.position_m = {cp.position_m.x, cp.position_m.y, cp.position_m.z};
  s.true_pose.rotation = Eigen::Quaterniond(cp.attitude.w, cp.attitude.x, cp.attitude.y, cp.attitude.z);
  s.altitude_m = cp.position_m.z;
  s.noise_std = noise_std;
  const Vector3d axis = s.true_pose.rotation * Vector3d::UnitZ();  // optical axis in the world
  s.tilt_rad = std::acos(std::clamp(-axis.z(), -1.0, 1.0));
  for (const physics::Victim& v : config.victims) {
    s.victims.push_back({Vector2d(v.x_m, v.y_m), Classify(v, s, config)});
  }
  return s;
}

}  // namespace

Result<std::vector<Scene>> RenderTiltedScenes(const SceneSetParams& p, double differential, double burst_s) {
  Result<physics::Airframe> x500 = physics::LoadAirframe(std::string(SWARMBOX_TRIALS_DIR) + "/airframes/x500.yaml");
  if (!x500) return x500.error().Context("loading the x500 airframe for the camera");
  std::mt19937_64 rng(p.seed);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<Scene> scenes;
  int world_index = 0;
  while (static_cast<int>(scenes.size()) < p.scenes) {
    const physics::WorldConfig config = MakeWorld(rng, 1000 + world_index++);
    Result<std::unique_ptr<physics::World>> world = physics::World::Create(config, {.seed = rng()});
    if (!world) return world.error().Context("creating perception world");
    const int count = std::min(p.scenes_per_world, p.scenes - static_cast<int>(scenes.size()));
    const double hover_u = x500->HoverRotorSpeed() / x500->motor.max_rot_velocity_rad_s;
    std::vector<std::size_t> drones;
    std::vector<std::vector<double>> commands;
    std::vector<double> noise;
    for (int i = 0; i < count; ++i) {  // every drone is added before the first Step()
      const double altitude = p.min_altitude_m + (p.max_altitude_m - p.min_altitude_m) * unit(rng);
      const physics::Victim& v = config.victims[static_cast<std::size_t>(rng() % config.victims.size())];
      const double half_w = altitude * std::tan(x500->camera.hfov_rad / 2);
      const Vector2d centre = Vector2d(v.x_m, v.y_m) + 0.5 * half_w * Vector2d(2 * unit(rng) - 1, 2 * unit(rng) - 1);
      physics::Airframe af = *x500;
      af.camera.noise_std = p.min_noise_std + (p.max_noise_std - p.min_noise_std) * unit(rng);
      physics::DroneSpawn spawn;
      spawn.name = "tilt_" + std::to_string(i);
      spawn.airframe = af;
      spawn.position_m = {centre.x(), centre.y(), altitude - af.base_height_m};
      spawn.yaw_rad = 2 * std::numbers::pi * unit(rng);
      spawn.initial_throttle = hover_u;
      Result<std::size_t> d = (*world)->AddDrone(spawn);
      if (!d) return d.error().Context("placing camera drone");
      const double a = differential * (2 * unit(rng) - 1), b = differential * (2 * unit(rng) - 1);
      std::vector<double> u;
      for (const physics::RotorSpec& r : af.rotors) {
        u.push_back(hover_u + a * (r.position_m.x > 0 ? 1 : -1) + b * (r.position_m.y > 0 ? 1 : -1));
      }
      drones.push_back(*d);
      commands.push_back(std::move(u));
      noise.push_back(af.camera.noise_std);
    }
    const auto steps = static_cast<int>(std::lround(burst_s * 1e9 / static_cast<double>((*world)->options().control_period_ns)));
    for (int k = 0; k < steps; ++k) {
      for (std::size_t i = 0; i < drones.size(); ++i) {
        if (Status st = (*world)->SetActuators(drones[i], commands[i]); !st) return st.error();
      }
      (*world)->Step();
    }
    for (std::size_t i = 0; i < drones.size(); ++i) {
      physics::CameraImage img;
      (*world)->RenderCamera(drones[i], &img);
      scenes.push_back(SceneFromImage(std::move(img), config, noise[i]));
    }
  }
  return scenes;
}

double PerceptionScore::precision() const {
  const int positives = true_positives + false_positives;
  return positives == 0 ? 1.0 : static_cast<double>(true_positives) / positives;
}
double PerceptionScore::recall() const {
  return full_victims == 0 ? 1.0 : static_cast<double>(true_positives) / full_victims;
}
static double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::floor(q * static_cast<double>(v.size() - 1) + 0.5));
  return v[i];
}
double PerceptionScore::median_error_m() const { return Quantile(errors_m, 0.5); }
double PerceptionScore::p90_error_m() const { return Quantile(errors_m, 0.9); }

PerceptionScore ScorePerception(const std::vector<Scene>& scenes, const PerceptionParams& params,
                                const PoseNoise& noise, double match_radius_m) {
  PerceptionScore score;
  VictimPerception perception(params);
  std::mt19937_64 rng(noise.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<GroundDetection> ready;
  double t = 0.0;
  for (const Scene& s : scenes) {
    ++score.scenes;
    OpticalPose est = s.true_pose;
    est.position_m += noise.position_sigma_m * Vector3d(n01(rng), n01(rng), n01(rng));
    const Vector3d rv = noise.attitude_sigma_rad * Vector3d(n01(rng), n01(rng), n01(rng));
    if (rv.norm() > 0) est.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(rv.norm(), rv.normalized())) * est.rotation;
    cv::Mat bgr(s.image.height_px, s.image.width_px, CV_8UC3, const_cast<std::uint8_t*>(s.image.bgr.data()));
    perception.ProcessFrame(bgr, s.intrinsics, est, t);
    ready.clear();
    perception.PopVisible(t + params.latency_s, &ready);
    t += 1.0;
    std::vector<bool> matched(s.victims.size(), false);
    for (const SceneVictim& v : s.victims) {
      score.full_victims += v.visibility == Visibility::kFull ? 1 : 0;
      score.partial_victims += v.visibility == Visibility::kPartial ? 1 : 0;
    }
    for (const GroundDetection& d : ready) {
      std::size_t best = s.victims.size();
      double best_d = match_radius_m;
      for (std::size_t i = 0; i < s.victims.size(); ++i) {
        if (s.victims[i].visibility == Visibility::kAbsent) continue;
        const double e = (s.victims[i].position_m - d.position_m.head<2>()).norm();
        if (e <= best_d) {
          best_d = e;
          best = i;
        }
      }
      if (best == s.victims.size()) {
        ++score.false_positives;
      } else if (s.victims[best].visibility == Visibility::kPartial) {
        ++score.partial_detected;
      } else if (!matched[best]) {
        matched[best] = true;
        ++score.true_positives;
        score.errors_m.push_back(best_d);
      } else {
        ++score.false_positives;  // a second detection of the same victim
      }
    }
  }
  return score;
}

}  // namespace swarmbox::swarm::testing
