#include "perception_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <string>

#include <opencv2/core.hpp>

#include "swarmbox/physics/airframe.hpp"
#include "swarmbox/physics/ground_renderer.hpp"
#include "swarmbox/physics/thermal_renderer.hpp"
#include "swarmbox/physics/world.hpp"
#include "swarmbox/physics/world_config.hpp"
#include "swarmbox/report/trial_record.hpp"
#include "swarmbox/report/trial_series.hpp"

#ifndef SWARMBOX_TRIALS_DIR
#error "SWARMBOX_TRIALS_DIR must point at the project's trials/ folder"
#endif

namespace swarmbox::perception_scenes {
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
SceneVictim Classify(const physics::Victim& v, const Scene& scene, const physics::WorldConfig& world) {
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
  std::size_t inside = 0, near = 0, hidden = 0, seen = 0;
  for (const Vector2d& q : pts) {
    const Vector3d g(q.x(), q.y(), 0.0);
    const std::optional<Vector2d> px = ProjectToPixel(g, scene.intrinsics, scene.true_pose);
    if (!px) continue;
    if (px->x() >= 1 && px->y() >= 1 && px->x() <= w - 2 && px->y() <= hgt - 2) ++inside;
    if (px->x() >= -1 && px->y() >= -1 && px->x() <= w && px->y() <= hgt) ++near;
    const bool in = px->x() >= 1 && px->y() >= 1 && px->x() <= w - 2 && px->y() <= hgt - 2;
    bool blocked = false;
    for (const physics::ObstacleBox& b : world.obstacles) {
      if (SegmentHitsBox(scene.true_pose.position_m, g, b)) {
        blocked = true;
        break;
      }
    }
    hidden += blocked ? 1 : 0;
    seen += in && !blocked ? 1 : 0;
  }
  SceneVictim out{Vector2d(v.x_m, v.y_m), Visibility::kPartial,
                  static_cast<double>(seen) / static_cast<double>(pts.size())};
  if (near == 0) out.visibility = Visibility::kAbsent;
  else if (inside == pts.size() && hidden == 0) out.visibility = Visibility::kFull;
  return out;
}

// The renderer's truth replaces the outline estimate of Classify (it knows cover and poses).
void SetVisibleFractions(const physics::WorldConfig& config, const std::vector<physics::VisiblePerson>& people,
                         Scene* s) {
  for (std::size_t i = 0; i < config.victims.size(); ++i) {
    double f = 0.0;
    for (const physics::VisiblePerson& p : people) {
      if (p.id == config.victims[i].id) f = p.visible_fraction;
    }
    s->victims[i].visible_fraction = f;
  }
}

physics::Bgr Jitter(std::mt19937_64& rng, physics::Bgr c, int amount) {
  std::uniform_int_distribution<int> j(-amount, amount);
  for (auto& x : c) x = static_cast<std::uint8_t>(std::clamp(x + j(rng), 0, 255));
  return c;
}

// The ground: a terrain kind and water, a time of day and overcast, half the boxes trees.
void VaryGround(std::mt19937_64& rng, const SceneSetParams& p, physics::WorldConfig* w) {
  std::uniform_real_distribution<double> unit(0, 1);
  static constexpr physics::TerrainKind kTerrains[] = {physics::TerrainKind::kGrass, physics::TerrainKind::kSoil,
                                                       physics::TerrainKind::kGravel, physics::TerrainKind::kRubble,
                                                       physics::TerrainKind::kMixed};
  physics::Terrain terrain;
  terrain.kind = kTerrains[rng() % 5];
  // The draw above stays, so that the rest of the world is what the all-kinds mix would draw.
  if (p.distractor_mix == DistractorMix::kConesRubble) terrain.kind = physics::TerrainKind::kRubble;
  terrain.water_fraction = unit(rng) < 0.3 ? 0.15 * unit(rng) : 0.0;
  w->terrain = terrain;
  physics::Lighting light;
  light.time_of_day_h = 7.0 + 11.0 * unit(rng);
  light.overcast = unit(rng);
  w->lighting = light;
  for (physics::ObstacleBox& b : w->obstacles) {
    if (unit(rng) < 0.5) b.kind = physics::ObstacleKind::kTree;
  }
}

// The people: a pose (lying most often), clothing (one in six keeps the hi-vis figure), cover.
void VaryPeople(std::mt19937_64& rng, const SceneSetParams& p, physics::WorldConfig* w) {
  std::uniform_real_distribution<double> unit(0, 1);
  // Clothing: greens, browns, greys, dark and bright colours (BGR).
  static constexpr physics::Bgr kClothes[] = {
      {40, 90, 40},   {60, 110, 70},  {50, 80, 60},   {40, 70, 110}, {30, 60, 90},  {60, 90, 120},
      {110, 110, 110}, {70, 70, 70},  {150, 150, 150}, {90, 40, 20},  {30, 30, 30},  {220, 220, 220},
      {30, 30, 200},  {30, 200, 230}, {200, 90, 30},  {160, 100, 230}, {0, 120, 255}, {120, 60, 140}};
  for (physics::Victim& v : w->victims) {
    const double pose = unit(rng);
    v.pose = pose < 0.55 ? physics::VictimPose::kLying
             : pose < 0.75 ? physics::VictimPose::kCurled
             : pose < 0.92 ? physics::VictimPose::kSitting
                           : physics::VictimPose::kStanding;
    if (unit(rng) >= 1.0 / 6.0) v.clothing_bgr = Jitter(rng, kClothes[rng() % std::size(kClothes)], 15);
    v.cover = unit(rng) < p.occluded_fraction ? 0.2 + 0.6 * unit(rng) : 0.0;
  }
}

// p.distractors of random kinds 2-9 m from each person (tarps and backpacks in the generated
// worlds' colours).
void AddDistractors(std::mt19937_64& rng, const SceneSetParams& p, physics::WorldConfig* w) {
  std::uniform_real_distribution<double> unit(0, 1);
  static constexpr physics::DistractorKind kKinds[] = {physics::DistractorKind::kTarp, physics::DistractorKind::kCone,
                                                       physics::DistractorKind::kBackpack,
                                                       physics::DistractorKind::kDebris, physics::DistractorKind::kRock};
  const std::vector<physics::Victim> people = w->victims;
  for (const physics::Victim& v : people) {
    for (int k = 0; k < p.distractors; ++k) {
      physics::Distractor d;
      d.kind = kKinds[rng() % std::size(kKinds)];
      if (p.distractor_mix == DistractorMix::kConesRubble) d.kind = physics::DistractorKind::kCone;
      const double r = 2.0 + 7.0 * unit(rng), a = 2 * std::numbers::pi * unit(rng);
      d.x_m = v.x_m + r * std::cos(a);
      d.y_m = v.y_m + r * std::sin(a);
      d.heading_rad = 2 * std::numbers::pi * unit(rng);
      d.size_m = physics::DefaultSizeM(d.kind) * (0.7 + 0.6 * unit(rng));
      d.colour_bgr = physics::DefaultColour(d.kind);
      if (d.kind == physics::DistractorKind::kTarp) d.colour_bgr = kTarpColours[rng() % std::size(kTarpColours)];
      if (d.kind == physics::DistractorKind::kBackpack) {
        d.colour_bgr = kBackpackColours[rng() % std::size(kBackpackColours)];
      }
      d.colour_bgr = Jitter(rng, d.colour_bgr, 20);
      w->distractors.push_back(d);
    }
  }
}

// 8 victims at random headings, at least 6 m apart.
void PlaceVictims(std::mt19937_64& rng, physics::WorldConfig* w) {
  std::uniform_real_distribution<double> coord(-80, 80), unit(0, 1);
  while (w->victims.size() < 8) {
    physics::Victim v;
    v.id = "v" + std::to_string(w->victims.size() + 1);
    v.x_m = coord(rng);
    v.y_m = coord(rng);
    v.heading_rad = 2 * std::numbers::pi * unit(rng);
    bool ok = true;
    for (const physics::Victim& o : w->victims) ok = ok && std::hypot(o.x_m - v.x_m, o.y_m - v.y_m) > 6.0;
    if (ok) w->victims.push_back(v);
  }
}

// Up to 12 boxes 1-8 m tall as clutter, kept 2 m clear of the victims.
void PlaceObstacles(std::mt19937_64& rng, physics::WorldConfig* w) {
  std::uniform_real_distribution<double> coord(-80, 80), unit(0, 1);
  int attempts = 0;
  while (w->obstacles.size() < 12 && ++attempts < 1000) {
    physics::ObstacleBox b;
    b.id = "box" + std::to_string(w->obstacles.size());
    b.size_m = {2 + 8 * unit(rng), 2 + 8 * unit(rng), 1 + 7 * unit(rng)};
    b.center_m = {coord(rng), coord(rng), b.size_m.z / 2};
    b.yaw_rad = std::numbers::pi * unit(rng);
    const double reach = std::hypot(b.size_m.x, b.size_m.y) / 2 + 2.0 + 1.0;  // 2 m clear + figure
    bool ok = true;
    for (const physics::Victim& v : w->victims) ok = ok && std::hypot(v.x_m - b.center_m.x, v.y_m - b.center_m.y) > reach;
    if (ok) w->obstacles.push_back(b);
  }
}

// The hi-vis look's occlusion and distractors: low slabs over part of a figure, small debris boxes.
void AddSlabsAndDebris(std::mt19937_64& rng, const SceneSetParams& p, physics::WorldConfig* w) {
  std::uniform_real_distribution<double> unit(0, 1);
  for (const physics::Victim& v : w->victims) {
    if (p.occluded_fraction > 0 && unit(rng) < p.occluded_fraction) {
      physics::ObstacleBox b;
      b.id = "slab" + std::to_string(w->obstacles.size());
      b.size_m = {0.5 + 0.7 * unit(rng), 0.4 + 0.5 * unit(rng), 0.3 + 0.3 * unit(rng)};
      // Along the figure, from the feet (-0.9 m) to the head (+0.8 m).
      const double along = -0.9 + 1.7 * unit(rng);
      b.center_m = {v.x_m + along * std::cos(v.heading_rad), v.y_m + along * std::sin(v.heading_rad), b.size_m.z / 2};
      b.yaw_rad = std::numbers::pi * unit(rng);
      w->obstacles.push_back(b);
    }
    for (int k = 0; k < p.distractors; ++k) {
      physics::ObstacleBox b;
      b.id = "debris" + std::to_string(w->obstacles.size());
      b.size_m = {0.3 + 1.2 * unit(rng), 0.3 + 0.8 * unit(rng), 0.1 + 0.5 * unit(rng)};
      const double r = 2.5 + 6.0 * unit(rng), a = 2 * std::numbers::pi * unit(rng);
      b.center_m = {v.x_m + r * std::cos(a), v.y_m + r * std::sin(a), b.size_m.z / 2};
      b.yaw_rad = std::numbers::pi * unit(rng);
      w->obstacles.push_back(b);
    }
  }
}

physics::WorldConfig MakeWorld(std::mt19937_64& rng, int index, const SceneSetParams& p) {
  physics::WorldConfig w;
  w.name = "perception_" + std::to_string(index);
  w.size_x_m = 200;
  w.size_y_m = 200;
  w.ground_texture_seed = rng();
  PlaceVictims(rng, &w);
  PlaceObstacles(rng, &w);
  // Occluders, distractors and the varied look draw from the generator only when asked for, so the
  // scene sets of the defaults stay what they were.
  if (p.varied_look) {
    VaryGround(rng, p, &w);
    VaryPeople(rng, p, &w);
    AddDistractors(rng, p, &w);
    return w;
  }
  AddSlabsAndDebris(rng, p, &w);
  return w;
}

Result<physics::Airframe> CameraAirframe() {
  Result<physics::Airframe> x500 = physics::LoadAirframe(std::string(SWARMBOX_TRIALS_DIR) + "/airframes/x500.yaml");
  if (!x500) return x500.error().Context("loading the x500 airframe for the camera");
  return x500;
}

// A camera drone `name` over `centre` at `altitude` [m] above the ground, its camera's noise
// `noise_std`, heading `yaw_rad`.
physics::DroneSpawn CameraSpawn(const physics::Airframe& x500, std::string name, const Vector2d& centre,
                                double altitude, double noise_std, double yaw_rad) {
  physics::Airframe af = x500;
  af.camera.noise_std = noise_std;
  physics::DroneSpawn spawn;
  spawn.name = std::move(name);
  spawn.airframe = af;
  spawn.position_m = {centre.x(), centre.y(), altitude - af.base_height_m};
  spawn.yaw_rad = yaw_rad;
  return spawn;
}

// The scene of a rendered image: intrinsics, true pose and altitude from the image, each victim
// classified (the renderer's visible fractions). The tilt is left at 0 (WithTilt measures it).
Scene SceneFromImage(physics::CameraImage image, const physics::WorldConfig& config, double noise_std,
                     const std::vector<physics::VisiblePerson>& people) {
  Scene s;
  s.image = std::move(image);
  s.intrinsics = {s.image.intrinsics.fx_px, s.image.intrinsics.fy_px, s.image.intrinsics.cx_px,
                  s.image.intrinsics.cy_px};
  const physics::Pose& cp = s.image.camera_pose;
  s.true_pose.position_m = {cp.position_m.x, cp.position_m.y, cp.position_m.z};
  s.true_pose.rotation = Eigen::Quaterniond(cp.attitude.w, cp.attitude.x, cp.attitude.y, cp.attitude.z);
  s.altitude_m = cp.position_m.z;
  s.noise_std = noise_std;
  for (const physics::Victim& v : config.victims) {
    s.victims.push_back(Classify(v, s, config));
  }
  SetVisibleFractions(config, people, &s);
  return s;
}

// The scene with its tilt: the angle between the optical axis and straight down.
Scene WithTilt(Scene s) {
  const Vector3d axis = s.true_pose.rotation * Vector3d::UnitZ();  // optical axis in the world
  s.tilt_rad = std::acos(std::clamp(-axis.z(), -1.0, 1.0));
  return s;
}

// Renders drone `drone`'s camera in `world` into a scene.
Scene SceneOfCamera(physics::World& world, std::size_t drone, const physics::WorldConfig& config, double noise_std) {
  physics::CameraImage img;
  std::vector<physics::VisiblePerson> people;
  world.RenderCamera(drone, &img, &people);
  return SceneFromImage(std::move(img), config, noise_std, people);
}

// A nadir view's centre: mostly near a victim (up to near_victim_offset half footprints away),
// else (near_distractor_fraction of the rest) near a distractor the same way, else anywhere in
// the central 160 x 160 m.
Vector2d ViewCentre(std::mt19937_64& rng, const SceneSetParams& p, const physics::WorldConfig& config, double half_w) {
  std::uniform_real_distribution<double> unit(0, 1);
  double x_m = 0, y_m = 0;
  if (unit(rng) < p.near_victim_fraction) {
    const physics::Victim& v = config.victims[static_cast<std::size_t>(rng() % config.victims.size())];
    x_m = v.x_m;
    y_m = v.y_m;
  } else if (p.near_distractor_fraction > 0 && !config.distractors.empty() &&
             unit(rng) < p.near_distractor_fraction) {  // (no draw without it: older sets stay as they were)
    const physics::Distractor& d =
        config.distractors[static_cast<std::size_t>(rng() % config.distractors.size())];
    x_m = d.x_m;
    y_m = d.y_m;
  } else {
    return Vector2d(160 * unit(rng) - 80, 160 * unit(rng) - 80);
  }
  return Vector2d(x_m, y_m) + p.near_victim_offset * half_w * Vector2d(2 * unit(rng) - 1, 2 * unit(rng) - 1);
}

// `count` nadir views of one world from camera drones added to it, onto *scenes.
Status RenderNadirViews(std::mt19937_64& rng, const SceneSetParams& p, const physics::Airframe& x500,
                        const physics::WorldConfig& config, physics::World& world, int count, std::vector<Scene>* scenes) {
  std::uniform_real_distribution<double> unit(0, 1);
  for (int i = 0; i < count; ++i) {
    const double altitude = p.min_altitude_m + (p.max_altitude_m - p.min_altitude_m) * unit(rng);
    const double yaw = 2 * std::numbers::pi * unit(rng) - std::numbers::pi;
    const double half_w = altitude * std::tan(x500.camera.hfov_rad / 2);
    const Vector2d centre = ViewCentre(rng, p, config, half_w);
    const double noise_std = p.min_noise_std + (p.max_noise_std - p.min_noise_std) * unit(rng);
    const physics::DroneSpawn spawn = CameraSpawn(x500, "cam_" + std::to_string(i), centre, altitude, noise_std, yaw);
    Result<std::size_t> d = world.AddDrone(spawn);
    if (!d) return d.error().Context("placing camera drone");
    scenes->push_back(SceneOfCamera(world, *d, config, noise_std));
    if (p.thermal) {
      scenes->back().thermal.emplace();
      if (auto s = world.RenderThermal(*d, &*scenes->back().thermal); !s)
        return s.error().Context("thermal camera");
    }
  }
  return Ok{};
}

// A world's tilted camera drones: spawned hovering, each with its differential rotor command.
struct TiltedDrones {
  std::vector<std::size_t> drones;
  std::vector<std::vector<double>> commands;
  std::vector<double> noise;
};

Status AddTiltedDrones(std::mt19937_64& rng, const SceneSetParams& p, const physics::Airframe& x500,
                       const physics::WorldConfig& config, double differential, int count, physics::World& world,
                       TiltedDrones* out) {
  std::uniform_real_distribution<double> unit(0, 1);
  const double hover_u = x500.HoverRotorSpeed() / x500.motor.max_rot_velocity_rad_s;
  for (int i = 0; i < count; ++i) {  // every drone is added before the first Step()
    const double altitude = p.min_altitude_m + (p.max_altitude_m - p.min_altitude_m) * unit(rng);
    const physics::Victim& v = config.victims[static_cast<std::size_t>(rng() % config.victims.size())];
    const double half_w = altitude * std::tan(x500.camera.hfov_rad / 2);
    const Vector2d centre = Vector2d(v.x_m, v.y_m) + 0.5 * half_w * Vector2d(2 * unit(rng) - 1, 2 * unit(rng) - 1);
    const double noise_std = p.min_noise_std + (p.max_noise_std - p.min_noise_std) * unit(rng);
    const double yaw = 2 * std::numbers::pi * unit(rng);
    physics::DroneSpawn spawn = CameraSpawn(x500, "tilt_" + std::to_string(i), centre, altitude, noise_std, yaw);
    spawn.initial_throttle = hover_u;
    Result<std::size_t> d = world.AddDrone(spawn);
    if (!d) return d.error().Context("placing camera drone");
    const double a = differential * (2 * unit(rng) - 1), b = differential * (2 * unit(rng) - 1);
    std::vector<double> u;
    for (const physics::RotorSpec& r : x500.rotors) {
      u.push_back(hover_u + a * (r.position_m.x > 0 ? 1 : -1) + b * (r.position_m.y > 0 ? 1 : -1));
    }
    out->drones.push_back(*d);
    out->commands.push_back(std::move(u));
    out->noise.push_back(noise_std);
  }
  return Ok{};
}

// burst_s of simulated flight with every drone on its command.
Status FlyBurst(const TiltedDrones& tilted, double burst_s, physics::World& world) {
  const auto steps = static_cast<int>(std::lround(burst_s * 1e9 / static_cast<double>(world.options().control_period_ns)));
  for (int k = 0; k < steps; ++k) {
    for (std::size_t i = 0; i < tilted.drones.size(); ++i) {
      if (Status st = world.SetActuators(tilted.drones[i], tilted.commands[i]); !st) return st.error();
    }
    world.Step();
  }
  return Ok{};
}

}  // namespace

worlds::GenerateSpec SarRubbleSpec() {
  return {.kind = worlds::WorldKind::kRubbleField, .size_m = {160, 160}, .victims = 4, .obstacles = 30, .distractors = 25};
}

namespace {

// A generated world from `spec`, its seed drawn from rng (below 1e9, as a trial's world seed is).
Result<physics::WorldConfig> GeneratedWorld(std::mt19937_64& rng, const worlds::GenerateSpec& spec) {
  const std::uint64_t seed = rng() % 1'000'000'000ULL;
  Result<std::string> text = worlds::GenerateWorld(spec, seed);
  if (!text) return text.error().Context("generating a perception world");
  Result<yaml::Node> root = yaml::Parse(*text, "generated world " + std::to_string(seed));
  if (!root) return root.error();
  return physics::ParseWorld(*root, "generated world " + std::to_string(seed));
}

}  // namespace

swarm::ThermalView ThermalViewOf(const physics::ThermalImage& t) {
  cv::Mat kelvin;
  cv::Mat(t.height_px, t.width_px, CV_16U, const_cast<std::uint16_t*>(t.centikelvin.data()))
      .convertTo(kelvin, CV_32F, 1.0 / physics::kThermalCountsPerK);
  const physics::Pose& pose = t.camera_pose;
  return {kelvin,
          {t.intrinsics.fx_px, t.intrinsics.fy_px, t.intrinsics.cx_px, t.intrinsics.cy_px},
          {Vector3d(pose.position_m.x, pose.position_m.y, pose.position_m.z),
           Eigen::Quaterniond(pose.attitude.w, pose.attitude.x, pose.attitude.y, pose.attitude.z)}};
}

namespace {

// The patch at ground point (x, y) into *out when it lies in the frame.
void AddThermalPatch(const swarm::ThermalView& view, double x, double y, bool person, int world,
                     std::vector<ThermalPatch>* out) {
  cv::Mat patch;
  if (!swarm::ThermalPatchAt(view, Vector3d(x, y, 0.0), &patch)) return;
  out->push_back({std::vector<float>(patch.begin<float>(), patch.end<float>()), person, world});
}

// A point just outside obstacle `b`'s footprint (along one of its sides, up to 1 m out).
Vector2d BesideObstacle(std::mt19937_64& rng, const physics::ObstacleBox& b) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double side = std::floor(unit(rng) * 4), along = unit(rng) - 0.5, out = 0.5 + 0.5 * unit(rng);
  const double hx = b.size_m.x / 2, hy = b.size_m.y / 2;
  const Vector2d local = side < 1   ? Vector2d(hx + out, 2 * along * hy)
                         : side < 2 ? Vector2d(-hx - out, 2 * along * hy)
                         : side < 3 ? Vector2d(2 * along * hx, hy + out)
                                    : Vector2d(2 * along * hx, -hy - out);
  const double c = std::cos(b.yaw_rad), s = std::sin(b.yaw_rad);
  return {b.center_m.x + c * local.x() - s * local.y(), b.center_m.y + s * local.x() + c * local.y()};
}

// Where a view of `w` is centred: near a person, a distractor, an obstacle's edge, or anywhere.
Vector2d ViewCentre(std::mt19937_64& rng, const physics::WorldConfig& w) {
  std::uniform_real_distribution<double> unit(0.0, 1.0), near(-4.0, 4.0);
  const double pick = unit(rng);
  const auto any = [&](std::size_t n) {
    return static_cast<std::size_t>(unit(rng) * static_cast<double>(n)) % n;
  };
  if (pick < 0.4 && !w.victims.empty()) {
    const physics::Victim& v = w.victims[any(w.victims.size())];
    return {v.x_m + near(rng), v.y_m + near(rng)};
  }
  if (pick < 0.7 && !w.distractors.empty()) {
    const physics::Distractor& d = w.distractors[any(w.distractors.size())];
    return {d.x_m + near(rng), d.y_m + near(rng)};
  }
  if (pick < 0.9 && !w.obstacles.empty()) return BesideObstacle(rng, w.obstacles[any(w.obstacles.size())]);
  const double half = 0.5 * SarRubbleSpec().size_m[0] - 10.0;
  return {(2 * unit(rng) - 1) * half, (2 * unit(rng) - 1) * half};
}

// One frame's patches (see RenderThermalPatches).
void FramePatches(std::mt19937_64& rng, const physics::WorldConfig& w, const physics::ThermalImage& img,
                  const std::vector<physics::VisiblePerson>& people, const ThermalPatchParams& p, int world,
                  std::vector<ThermalPatch>* out) {
  const swarm::ThermalView view = ThermalViewOf(img);
  std::normal_distribution<double> error(0.0, p.geolocation_sigma_m);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const physics::VisiblePerson& seen : people) {
    if (seen.visible_fraction < 0.5) continue;
    for (const physics::Victim& v : w.victims) {
      if (v.id == seen.id) AddThermalPatch(view, v.x_m + error(rng), v.y_m + error(rng), true, world, out);
    }
  }
  for (const physics::Distractor& d : w.distractors) AddThermalPatch(view, d.x_m, d.y_m, false, world, out);
  const Vector2d nadir(img.camera_pose.position_m.x, img.camera_pose.position_m.y);
  const Vector2d ground = nadir + Vector2d((unit(rng) - 0.5) * 12.0, (unit(rng) - 0.5) * 10.0);
  AddThermalPatch(view, ground.x(), ground.y(), false, world, out);
  if (!w.obstacles.empty()) {
    const auto i =
        static_cast<std::size_t>(unit(rng) * static_cast<double>(w.obstacles.size())) % w.obstacles.size();
    const Vector2d beside = BesideObstacle(rng, w.obstacles[i]);
    AddThermalPatch(view, beside.x(), beside.y(), false, world, out);
  }
}

}  // namespace

Result<std::vector<ThermalPatch>> RenderThermalPatches(const ThermalPatchParams& p) {
  Result<physics::Airframe> x500 = CameraAirframe();
  if (!x500) return x500.error();
  std::mt19937_64 rng(p.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<ThermalPatch> out;
  physics::ThermalImage img;
  std::vector<physics::VisiblePerson> people;
  for (int first = 0; first < p.views; first += p.views_per_world) {
    Result<physics::WorldConfig> w = GeneratedWorld(rng, SarRubbleSpec());
    if (!w) return w.error();
    physics::ThermalRenderer renderer(*w);
    const int world = first / p.views_per_world;
    for (int i = first; i < std::min(p.views, first + p.views_per_world); ++i) {
      const Vector2d c = ViewCentre(rng, *w);
      const double alt = p.min_altitude_m + (p.max_altitude_m - p.min_altitude_m) * unit(rng);
      const double yaw = 2 * std::numbers::pi * unit(rng);
      const physics::Pose body{physics::Vec3{c.x(), c.y(), alt},
                               physics::Quat{std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)}};
      renderer.Render(body, x500->thermal, rng(), &img, &people);
      FramePatches(rng, *w, img, people, p, world, &out);
    }
  }
  return out;
}

Result<std::vector<Scene>> RenderScenes(const SceneSetParams& p) {
  Result<physics::Airframe> x500 = CameraAirframe();
  if (!x500) return x500.error();
  std::mt19937_64 rng(p.seed);
  std::vector<Scene> scenes;
  scenes.reserve(static_cast<std::size_t>(p.scenes));
  int world_index = 0;
  while (static_cast<int>(scenes.size()) < p.scenes) {
    physics::WorldConfig config;
    if (p.generated) {
      Result<physics::WorldConfig> generated = GeneratedWorld(rng, *p.generated);
      if (!generated) return generated.error();
      config = std::move(*generated);
    } else {
      config = MakeWorld(rng, world_index, p);
    }
    Result<std::unique_ptr<physics::World>> world = physics::World::Create(config, {.seed = rng()});
    if (!world) return world.error().Context("creating perception world");
    const int count = std::min(p.scenes_per_world, p.scenes - static_cast<int>(scenes.size()));
    if (Status st = RenderNadirViews(rng, p, *x500, config, **world, count, &scenes); !st) return st.error();
    ++world_index;
  }
  return scenes;
}

Result<Scene> RenderView(const physics::WorldConfig& config, const Vector2d& centre, double altitude,
                         double yaw, double noise_std) {
  Result<physics::Airframe> x500 = CameraAirframe();
  if (!x500) return x500.error();
  Result<std::unique_ptr<physics::World>> world = physics::World::Create(config, {.seed = 1});
  if (!world) return world.error().Context("creating perception world");
  Result<std::size_t> d = (*world)->AddDrone(CameraSpawn(*x500, "cam", centre, altitude, noise_std, yaw));
  if (!d) return d.error().Context("placing camera drone");
  return WithTilt(SceneOfCamera(**world, *d, config, noise_std));
}

Result<std::vector<Scene>> RenderTiltedScenes(const SceneSetParams& p, double differential, double burst_s) {
  Result<physics::Airframe> x500 = CameraAirframe();
  if (!x500) return x500.error();
  std::mt19937_64 rng(p.seed);
  std::vector<Scene> scenes;
  int world_index = 0;
  while (static_cast<int>(scenes.size()) < p.scenes) {
    const physics::WorldConfig config = MakeWorld(rng, 1000 + world_index++, p);
    Result<std::unique_ptr<physics::World>> world = physics::World::Create(config, {.seed = rng()});
    if (!world) return world.error().Context("creating perception world");
    const int count = std::min(p.scenes_per_world, p.scenes - static_cast<int>(scenes.size()));
    TiltedDrones tilted;
    if (Status st = AddTiltedDrones(rng, p, *x500, config, differential, count, **world, &tilted); !st) return st.error();
    if (Status st = FlyBurst(tilted, burst_s, **world); !st) return st.error();
    for (std::size_t i = 0; i < tilted.drones.size(); ++i) {
      scenes.push_back(WithTilt(SceneOfCamera(**world, tilted.drones[i], config, tilted.noise[i])));
    }
  }
  return scenes;
}

namespace {

// A camera drone's state in the replay: where its last frame was taken.
struct ReplayCamera {
  bool taken = false;
  Vector2d last_xy = Vector2d::Zero();
  double last_t_s = 0.0;
  std::uint64_t frames = 0;

  // Whether the camera takes a frame at `xy` and `t_s` (its trigger distance, or its
  // trigger_interval_max_s while it does not move: a hover, a revisit's close look; else its
  // rate), as the physics server's camera_trigger.hpp; when it does, it counts it. (Without the
  // wait a replay had no frame of a close look at all.)
  bool Take(const Vector2d& xy, double t_s, const physics::CameraSpec& camera) {
    const bool moved = (xy - last_xy).norm() >= camera.trigger_distance_m;
    // (the server decides on its rate_hz grid: the wait ends at the first slot past the interval)
    const double slots = std::floor((t_s - last_t_s) * camera.rate_hz + 1e-6);
    const bool waited =
        camera.trigger_interval_max_s > 0 && slots / camera.rate_hz >= camera.trigger_interval_max_s - 1e-9;
    const bool due =
        !taken || (camera.trigger_distance_m > 0 ? moved || waited : t_s - last_t_s >= 1.0 / camera.rate_hz);
    if (!due) return false;
    taken = true;
    last_xy = xy;
    last_t_s = t_s;
    ++frames;
    return true;
  }
};

// A frame's pixel-noise seed: the drone's name (FNV-1a) and its frame count.
std::uint64_t ReplayNoiseSeed(std::string_view drone, std::uint64_t frame) {
  std::uint64_t h = 1469598103934665603ULL;
  for (const char c : drone) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  return h ^ (frame << 20);
}

// Truth row r's frame: the colour camera's (and with `thermal` the thermal camera's) at its pose.
ReplayFrame RenderReplayFrame(const report::TruthRow& r, std::uint64_t noise_seed,
                              const physics::WorldConfig& world, const physics::Airframe& x500,
                              physics::GroundRenderer& renderer, physics::ThermalRenderer* thermal,
                              physics::CameraImage& image, std::vector<physics::VisiblePerson>& people) {
  const physics::Pose body{{r.x_m, r.y_m, r.z_m}, {r.qw, r.qx, r.qy, r.qz}};
  renderer.Render(body, {r.p_rad_s, r.q_rad_s, r.r_rad_s}, x500.camera, noise_seed, &image, &people);
  ReplayFrame frame{r.drone, r.t_s, WithTilt(SceneFromImage(image, world, x500.camera.noise_std, people))};
  if (thermal != nullptr) {
    frame.scene.thermal.emplace();
    thermal->Render(body, x500.thermal, noise_seed ^ 0x7E4A11ULL, &*frame.scene.thermal);
  }
  return frame;
}

// What reading truth.csv for a replay came to.
Status TruthStatus(bool read, bool attitude, const std::string& truth_path) {
  if (!read) {
    return Error(ErrorCode::kInvalidArgument,
                 "truth.csv cannot be read or has no t_s, drone, x_m, y_m, z_m header", truth_path);
  }
  if (!attitude) {
    return Error(ErrorCode::kInvalidArgument,
                 "truth.csv has no attitude and body rates (qw, qx, qy, qz, p_rad_s, q_rad_s, r_rad_s)",
                 truth_path);
  }
  return Ok{};
}

}  // namespace

Status ReplayTrial(const ReplayParams& params,
                   const std::function<void(const physics::WorldConfig&, const ReplayFrame&)>& on_frame) {
  Result<physics::WorldConfig> world = physics::LoadWorld(params.trial_dir + "/world.yaml");
  if (!world) return world.error().Context("replaying a trial (is it a generated world's trial folder?)");
  Result<physics::Airframe> x500 = CameraAirframe();
  if (!x500) return x500.error();
  const std::string truth_path = params.trial_dir + "/truth.csv";
  if (!std::filesystem::is_regular_file(truth_path)) {
    return Error(ErrorCode::kNotFound, "cannot read the trial's truth.csv", truth_path);
  }
  const physics::CameraSpec& camera = x500->camera;
  physics::GroundRenderer renderer(*world);
  std::unique_ptr<physics::ThermalRenderer> thermal;
  if (params.thermal) {
    if (!x500->thermal.enabled)
      return Error(ErrorCode::kInvalidArgument, "the x500 carries no thermal camera");
    thermal = std::make_unique<physics::ThermalRenderer>(*world);
  }
  std::map<std::string, ReplayCamera, std::less<>> cameras;
  physics::CameraImage image;
  std::vector<physics::VisiblePerson> people;
  bool attitude = true;
  const bool read = report::ReadTruthCsv(truth_path, [&](const report::TruthRow& r) {
    attitude = attitude && r.has_attitude;
    if (!attitude || !r.drone.starts_with(params.drone_prefix) || r.z_m < params.min_height_m ||
        r.z_m > params.max_height_m) {
      return;
    }
    ReplayCamera& cam = cameras[r.drone];
    if (!cam.Take(Vector2d(r.x_m, r.y_m), r.t_s, camera)) return;
    const ReplayFrame frame = RenderReplayFrame(r, ReplayNoiseSeed(r.drone, cam.frames), *world, *x500,
                                                renderer, thermal.get(), image, people);
    on_frame(*world, frame);
  });
  return TruthStatus(read, attitude, truth_path);
}

}  // namespace swarmbox::perception_scenes
