#include "swarmbox/physics/world.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <mutex>
#include <numbers>
#include <string>
#include <string_view>
#include <unordered_map>

#include "sensor_models.hpp"
#include "swarmbox/physics/ground_renderer.hpp"
#include "swarmbox/physics/thermal_renderer.hpp"

namespace swarmbox::physics {
namespace {

constexpr int kMaxContactsPerPair = 4;
constexpr std::size_t kMaxPartners = 8;          // contact partners tracked per drone
constexpr std::size_t kMaxPendingEvents = 1024;  // per Step(); more are counted and dropped
constexpr double kGroundCheckMarginM = 0.05;     // AABB bottom below this: test against the ground
constexpr std::int64_t kGroundPartner = -1;
constexpr std::int64_t kPayloadPartnerBase = 1'000'000;

void InitOdeOnce() {
  static std::once_flag once;
  std::call_once(once, [] { dInitODE2(0); });
  dAllocateODEDataForThread(dAllocateMaskAll);
}

Vec3 V(const dReal* p) { return {p[0], p[1], p[2]}; }

// ODE row-major 3x4 rotation: v_world = R v_body.
Vec3 RotR(const dReal* R, const Vec3& v) {
  return {R[0] * v.x + R[1] * v.y + R[2] * v.z, R[4] * v.x + R[5] * v.y + R[6] * v.z,
          R[8] * v.x + R[9] * v.y + R[10] * v.z};
}
Vec3 RotRT(const dReal* R, const Vec3& v) {
  return {R[0] * v.x + R[4] * v.y + R[8] * v.z, R[1] * v.x + R[5] * v.y + R[9] * v.z,
          R[2] * v.x + R[6] * v.y + R[10] * v.z};
}

struct GeomTag {
  enum Kind : std::uint8_t { kDrone, kPayload, kObstacle } kind;
  std::size_t index;
};

struct PendingEvent {
  EventKind kind;
  std::size_t a;
  std::int64_t partner;  // see *Partner constants; obstacle k: -(2 + k)
  double speed_m_s;
  std::int64_t time_ns;
  Vec3 position_m;   // kPayloadAtRest
  double tilt_deg;   // kPayloadAtRest
};

}  // namespace

struct World::Impl {
  struct Drone {
    std::string name;
    Airframe af;
    dBodyID body = nullptr;
    dGeomID geom = nullptr;
    std::unique_ptr<GeomTag> tag;
    std::size_t rotor_count = 0;
    std::array<double, 8> u{};
    std::array<double, 8> omega{};
    double alpha_up = 0, alpha_down = 0;  // per sub-step first-order factors
    // payload
    const PayloadSpec* payload = nullptr;
    dBodyID payload_body = nullptr;
    dGeomID payload_geom = nullptr;
    std::unique_ptr<GeomTag> payload_tag;
    dJointID sling = nullptr;
    double payload_drag = 0;
    bool payload_settling = false;       // released, not yet reported at rest
    std::int64_t payload_still_ns = -1;  // since when it has been slower than the rest speed; -1: moving
    dJointID pin = nullptr;
    Vec3 external_force;
    // state
    bool crashed = false;
    bool lost = false;
    bool gps_dropout = false;
    bool outside_geofence = false;
    Vec3 prev_velocity;
    Vec3 accel_world;
    std::unique_ptr<SensorSuite> sensors;
    SensorSample sample;
    std::array<std::int64_t, kMaxPartners> partners{}, prev_partners{};
    std::size_t partner_count = 0, prev_partner_count = 0;
  };

  WorldConfig config;
  WorldOptions options;
  dWorldID world = nullptr;
  // Broad phase (ours, not an ODE space: the hash space allocated and cost more than the rest of
  // the step with 100 drones). Geoms live in no space; every sub-step sorts the moving geoms'
  // AABBs along x (insertion sort: nearly sorted from the last sub-step) and sweeps.
  struct Bound {
    dReal aabb[6];  // min x, max x, min y, max y, min z, max z
    dGeomID geom;
    GeomTag* tag;
  };
  std::vector<Bound> bounds;
  std::vector<std::uint32_t> order;
  std::vector<dGeomID> obstacle_geoms;
  std::vector<std::array<dReal, 6>> obstacle_aabbs;
  dGeomID ground = nullptr;
  dJointGroupID contacts = nullptr;
  std::vector<std::unique_ptr<GeomTag>> obstacle_tags;
  std::vector<std::unique_ptr<Drone>> drones;
  struct NameHash {
    using is_transparent = void;
    std::size_t operator()(std::string_view s) const { return std::hash<std::string_view>{}(s); }
  };
  // drone name -> index: FindDrone in O(1), without allocating
  std::unordered_map<std::string, std::size_t, NameHash, std::equal_to<>> index_of;
  WindModel wind;
  Vec3 wind_now;
  std::unique_ptr<GroundRenderer> renderer;
  std::unique_ptr<ThermalRenderer> thermal;  // built on the first thermal frame
  EventSink* sink = nullptr;
  std::array<PendingEvent, kMaxPendingEvents> pending{};
  std::size_t pending_count = 0;
  std::uint64_t dropped_events = 0;
  std::int64_t time_ns = 0;
  std::uint64_t step = 0;
  double dt_s = 0;

  Impl(const WorldConfig& c, const WorldOptions& o) : config(c), options(o), wind(c.wind, MixSeed(o.seed, 0xA11)) {}

  ~Impl() {
    for (auto& d : drones) {
      if (d->sling) dJointDestroy(d->sling);
      if (d->pin) dJointDestroy(d->pin);
      if (d->payload_geom) dGeomDestroy(d->payload_geom);
      if (d->payload_body) dBodyDestroy(d->payload_body);
      dGeomDestroy(d->geom);
      dBodyDestroy(d->body);
    }
    if (contacts) dJointGroupDestroy(contacts);
    if (ground) dGeomDestroy(ground);
    for (dGeomID g : obstacle_geoms) dGeomDestroy(g);
    if (world) dWorldDestroy(world);
  }

  void Emit(EventKind kind, std::size_t a, std::int64_t partner, double speed) {
    if (pending_count == pending.size()) {
      ++dropped_events;
      return;
    }
    pending[pending_count++] = {kind, a, partner, speed, time_ns, Vec3{}, 0.0};
  }

  // After a step: a released payload that has stayed slower than kPayloadRestSpeed_m_s for
  // kPayloadRestTime_s is reported at rest, once.
  void WatchPayload(Drone& d, std::size_t i) {
    if (!d.payload_settling) return;
    if (Norm(V(dBodyGetLinearVel(d.payload_body))) >= kPayloadRestSpeed_m_s) {
      d.payload_still_ns = -1;
      return;
    }
    if (d.payload_still_ns < 0) d.payload_still_ns = time_ns;
    if (static_cast<double>(time_ns - d.payload_still_ns) * 1e-9 < kPayloadRestTime_s) return;
    d.payload_settling = false;
    const dReal* r = dBodyGetRotation(d.payload_body);  // row-major 3x4: r[10] = body z's world z
    const double tilt_deg = std::acos(std::clamp(static_cast<double>(r[10]), -1.0, 1.0)) * 180.0 / std::numbers::pi;
    if (pending_count == pending.size()) {
      ++dropped_events;
      return;
    }
    pending[pending_count++] = {EventKind::kPayloadAtRest, i, 0, 0.0, time_ns, V(dBodyGetPosition(d.payload_body)), tilt_deg};
  }

  std::string PartnerName(std::int64_t p) const {
    if (p == kGroundPartner) return "ground";
    if (p >= kPayloadPartnerBase) {
      const Drone& d = *drones[static_cast<std::size_t>(p - kPayloadPartnerBase)];
      return d.name + "/" + (d.payload ? d.payload->name : std::string("payload"));
    }
    if (p >= 0) return drones[static_cast<std::size_t>(p)].get()->name;
    return config.obstacles[static_cast<std::size_t>(-p - 2)].id;
  }

  // Records that drone `i` touches `partner` in this sub-step; true if it did not before.
  bool Touch(Drone& d, std::int64_t partner) {
    for (std::size_t k = 0; k < d.partner_count; ++k) {
      if (d.partners[k] == partner) return false;
    }
    if (d.partner_count < kMaxPartners) d.partners[d.partner_count++] = partner;
    for (std::size_t k = 0; k < d.prev_partner_count; ++k) {
      if (d.prev_partners[k] == partner) return false;
    }
    return true;
  }

  void Crash(std::size_t i, std::int64_t partner, double speed) {
    Drone& d = *drones[i];
    if (d.crashed) return;
    d.crashed = true;
    d.u.fill(0.0);
    Emit(EventKind::kCrash, i, partner, speed);
  }

  void OnDroneContact(std::size_t i, std::int64_t partner, const Vec3& other_velocity, const dReal* normal) {
    Drone& d = *drones[i];
    if (!Touch(d, partner)) return;
    const Vec3 rel = V(dBodyGetLinearVel(d.body)) - other_velocity;
    const double normal_speed = std::abs(Dot(rel, V(normal)));
    if (partner == kGroundPartner) {
      if (normal_speed > d.af.crash_speed_m_s) {
        Crash(i, partner, normal_speed);
      } else if (normal_speed > d.af.hard_landing_speed_m_s) {
        Emit(EventKind::kHardLanding, i, partner, normal_speed);
      }
      return;
    }
    const double speed = Norm(rel);
    // drone-drone pairs are reported once, by the lower index.
    if (partner < 0 || partner >= kPayloadPartnerBase || static_cast<std::size_t>(partner) > i) {
      Emit(EventKind::kCollision, i, partner, speed);
    }
    if (speed > d.af.crash_speed_m_s) Crash(i, partner, speed);
  }

  static void NearCallback(void* data, dGeomID g1, dGeomID g2) {
    auto* self = static_cast<Impl*>(data);
    auto* t1 = static_cast<GeomTag*>(dGeomGetData(g1));
    auto* t2 = static_cast<GeomTag*>(dGeomGetData(g2));
    if (t1 == nullptr || t2 == nullptr) return;
    if (t1->kind == GeomTag::kObstacle && t2->kind == GeomTag::kObstacle) return;
    if (t1->kind != GeomTag::kObstacle && t2->kind != GeomTag::kObstacle && t1->index == t2->index) return;
    self->Collide(g1, g2, t1, t2);
  }

  static std::int64_t PartnerId(const GeomTag* t) {
    switch (t->kind) {
      case GeomTag::kDrone:
        return static_cast<std::int64_t>(t->index);
      case GeomTag::kPayload:
        return kPayloadPartnerBase + static_cast<std::int64_t>(t->index);
      case GeomTag::kObstacle:
        break;
    }
    return -2 - static_cast<std::int64_t>(t->index);
  }

  void Collide(dGeomID g1, dGeomID g2, const GeomTag* t1, const GeomTag* t2) {
    std::array<dContact, kMaxContactsPerPair> cs{};
    const int n = dCollide(g1, g2, kMaxContactsPerPair, &cs[0].geom, sizeof(dContact));
    if (n <= 0) return;
    dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
    for (int k = 0; k < n; ++k) {
      dContact& c = cs[static_cast<std::size_t>(k)];
      c.surface.mode = dContactApprox1;
      c.surface.mu = 0.8;
      dJointID j = dJointCreateContact(world, contacts, &c);
      dJointAttach(j, b1, b2);
    }
    const dReal* normal = cs[0].geom.normal;
    const Vec3 v1 = b1 ? V(dBodyGetLinearVel(b1)) : Vec3{};
    const Vec3 v2 = b2 ? V(dBodyGetLinearVel(b2)) : Vec3{};
    const std::int64_t p1 = t1 ? PartnerId(t1) : kGroundPartner;
    const std::int64_t p2 = t2 ? PartnerId(t2) : kGroundPartner;
    if (t1 && t1->kind == GeomTag::kDrone) OnDroneContact(t1->index, p2, v2, normal);
    if (t2 && t2->kind == GeomTag::kDrone) OnDroneContact(t2->index, p1, v1, normal);
  }

  void ApplyForces(Drone& d) {
    const dReal* R = dBodyGetRotation(d.body);
    const Vec3 v_air_b = RotRT(R, V(dBodyGetLinearVel(d.body)) - wind_now);
    const Vec3 w_b = RotRT(R, V(dBodyGetAngularVel(d.body)));
    const MotorSpec& m = d.af.motor;
    Vec3 force, torque;
    for (std::size_t r = 0; r < d.rotor_count; ++r) {
      const double target = (d.crashed || d.lost) ? 0.0 : d.u[r] * m.max_rot_velocity_rad_s;
      double& om = d.omega[r];
      om += (target - om) * (target > om ? d.alpha_up : d.alpha_down);
      const double thrust = m.motor_constant * om * om;
      const RotorSpec& rs = d.af.rotors[r];
      const Vec3 hub_v = v_air_b + Cross(w_b, rs.position_m);
      const Vec3 drag{-om * m.rotor_drag_coefficient * hub_v.x, -om * m.rotor_drag_coefficient * hub_v.y, 0.0};
      const Vec3 f{drag.x, drag.y, thrust};
      force += f;
      torque += Cross(rs.position_m, f);
      // Rolling moment (Gazebo MulticopterMotorModel): -|omega| c_r v_perp, about the in-plane axes.
      torque += Vec3{-om * m.rolling_moment_coefficient * hub_v.x, -om * m.rolling_moment_coefficient * hub_v.y, 0.0};
      torque.z += (rs.ccw ? -1.0 : 1.0) * m.moment_constant * thrust;
    }
    const double speed = Norm(v_air_b);
    const Vec3& c = d.af.body_drag_coefficient;
    force += Vec3{-c.x * speed * v_air_b.x, -c.y * speed * v_air_b.y, -c.z * speed * v_air_b.z};
    dBodyAddRelForce(d.body, force.x, force.y, force.z);
    dBodyAddRelTorque(d.body, torque.x, torque.y, torque.z);
    if (d.external_force.x != 0 || d.external_force.y != 0 || d.external_force.z != 0) {
      dBodyAddForce(d.body, d.external_force.x, d.external_force.y, d.external_force.z);
    }
    if (d.payload_body) {
      const Vec3 pv = V(dBodyGetLinearVel(d.payload_body)) - wind_now;
      const double s = Norm(pv);
      dBodyAddForce(d.payload_body, -d.payload_drag * s * pv.x, -d.payload_drag * s * pv.y, -d.payload_drag * s * pv.z);
    }
  }

  static bool Overlap(const dReal* a, const dReal* b) {
    return a[0] <= b[1] && b[0] <= a[1] && a[2] <= b[3] && b[2] <= a[3] && a[4] <= b[5] && b[4] <= a[5];
  }

  void BroadPhase() {
    std::size_t n = 0;
    for (auto& d : drones) {
      Bound& b = bounds[n++];
      dGeomGetAABB(d->geom, b.aabb);
      b.geom = d->geom;
      b.tag = d->tag.get();
      if (d->payload_geom) {
        Bound& p = bounds[n++];
        dGeomGetAABB(d->payload_geom, p.aabb);
        p.geom = d->payload_geom;
        p.tag = d->payload_tag.get();
      }
    }
    // Insertion sort by min x.
    for (std::size_t i = 1; i < order.size(); ++i) {
      const std::uint32_t key = order[i];
      const dReal kx = bounds[key].aabb[0];
      std::size_t j = i;
      while (j > 0 && bounds[order[j - 1]].aabb[0] > kx) {
        order[j] = order[j - 1];
        --j;
      }
      order[j] = key;
    }
    for (std::size_t i = 0; i < order.size(); ++i) {
      const Bound& a = bounds[order[i]];
      for (std::size_t j = i + 1; j < order.size(); ++j) {
        const Bound& b = bounds[order[j]];
        if (b.aabb[0] > a.aabb[1]) break;
        if (Overlap(a.aabb, b.aabb)) NearCallback(this, a.geom, b.geom);
      }
      for (std::size_t k = 0; k < obstacle_geoms.size(); ++k) {
        if (Overlap(a.aabb, obstacle_aabbs[k].data())) {
          Collide(a.geom, obstacle_geoms[k], a.tag, static_cast<GeomTag*>(dGeomGetData(obstacle_geoms[k])));
        }
      }
      if (a.aabb[4] <= kGroundCheckMarginM) Collide(ground, a.geom, nullptr, a.tag);
    }
  }

  void SubStep() {
    for (auto& d : drones) ApplyForces(*d);
    for (auto& d : drones) {
      d->prev_partners = d->partners;
      d->prev_partner_count = d->partner_count;
      d->partner_count = 0;
    }
    BroadPhase();
    dWorldStep(world, dt_s);
    dJointGroupEmpty(contacts);
  }

  TrueKinematics Kinematics(const Drone& d) const {
    TrueKinematics k;
    k.position_m = V(dBodyGetPosition(d.body));
    k.velocity_m_s = V(dBodyGetLinearVel(d.body));
    k.accel_m_s2 = d.accel_world;
    const dReal* q = dBodyGetQuaternion(d.body);
    k.attitude = {q[0], q[1], q[2], q[3]};
    k.body_rates_rad_s = RotRT(dBodyGetRotation(d.body), V(dBodyGetAngularVel(d.body)));
    return k;
  }

  void SampleSensors(Drone& d) {
    d.sensors->Sample(time_ns, Kinematics(d), d.gps_dropout, &d.sample);
    d.sample.step = step;
  }

  // AddDrone's parts: the drone's bodies, geoms, motors and sensors (not yet in the world's
  // lists); its payload's body; then, once listed, the sling and the broad-phase slots.
  std::unique_ptr<Drone> NewDrone(const DroneSpawn& spawn, const PayloadSpec* payload, std::size_t index);
  void AddPayloadBody(Drone& d, const DroneSpawn& spawn, std::size_t index);
  void AttachSling(Drone& d, const DroneSpawn& spawn);
  void GrowBroadPhase(const Drone& added);

  void Dispatch() {
    if (sink != nullptr) {
      for (std::size_t k = 0; k < pending_count; ++k) {
        const PendingEvent& p = pending[k];
        PhysicsEvent e;
        e.t_s = static_cast<double>(p.time_ns) * 1e-9;
        e.kind = p.kind;
        e.a = drones[p.a]->name;
        if (p.kind == EventKind::kPayloadAttached || p.kind == EventKind::kPayloadReleased) {
          e.b = drones[p.a]->payload->name;
        } else if (p.kind == EventKind::kCollision || p.kind == EventKind::kCrash ||
                   p.kind == EventKind::kHardLanding) {
          e.b = PartnerName(p.partner);
        }
        e.speed_m_s = p.speed_m_s;
        e.position_m = p.position_m;
        e.tilt_deg = p.tilt_deg;
        sink->OnEvent(e);
      }
    }
    pending_count = 0;
  }

  double SwingAngle(const Drone& d) const {
    if (!d.sling) return 0.0;
    const Vec3 hook = V(dBodyGetPosition(d.body)) + RotR(dBodyGetRotation(d.body), d.payload->hook_m);
    const Vec3 s = V(dBodyGetPosition(d.payload_body)) - hook;
    const double n = Norm(s);
    return n > 1e-9 ? std::acos(std::clamp(-s.z / n, -1.0, 1.0)) : 0.0;
  }
};

const char* EventName(EventKind kind) {
  switch (kind) {
    case EventKind::kCollision: return "collision";
    case EventKind::kCrash: return "crash";
    case EventKind::kHardLanding: return "hard_landing";
    case EventKind::kPayloadAttached: return "payload_attached";
    case EventKind::kPayloadReleased: return "payload_released";
    case EventKind::kDroneLost: return "drone_lost";
    case EventKind::kDroneRejoined: return "drone_rejoined";
    case EventKind::kGeofence: return "geofence_breach";
    case EventKind::kPayloadAtRest: return "payload_at_rest";
  }
  return "unknown";
}

LogEvent PhysicsEvent::ToLogEvent(const std::string& node) const {
  LogEvent e(t_s, node, EventName(kind));
  if (kind == EventKind::kPayloadAtRest) {
    return e.Add("drone", a).Add("x", position_m.x, 2).Add("y", position_m.y, 2).Add("z", position_m.z, 2)
        .Add("tilt_deg", tilt_deg, 1);
  }
  e.Add("a", a);
  if (!b.empty()) e.Add("b", b);
  if (kind == EventKind::kCollision || kind == EventKind::kCrash || kind == EventKind::kHardLanding) {
    e.Add("speed", speed_m_s, 2);
  }
  return e;
}

World::World(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
World::~World() = default;

Result<std::unique_ptr<World>> World::Create(const WorldConfig& config, const WorldOptions& options) {
  if (options.substeps < 1 || options.control_period_ns <= 0 || options.control_period_ns % options.substeps != 0) {
    return Error(ErrorCode::kInvalidArgument,
                 "control_period_ns must be positive and a multiple of substeps (>= 1)");
  }
  if (config.size_x_m <= 0 || config.size_y_m <= 0 || config.gravity_m_s2 <= 0) {
    return Error(ErrorCode::kInvalidArgument, "world size and gravity must be positive", config.source);
  }
  InitOdeOnce();
  auto impl = std::make_unique<Impl>(config, options);
  Impl& w = *impl;
  w.dt_s = static_cast<double>(options.control_period_ns / options.substeps) * 1e-9;
  w.world = dWorldCreate();
  dWorldSetGravity(w.world, 0, 0, -config.gravity_m_s2);
  dWorldSetERP(w.world, 0.2);
  dWorldSetCFM(w.world, 1e-7);
  dWorldSetContactSurfaceLayer(w.world, 0.001);
  dWorldSetContactMaxCorrectingVel(w.world, 0.5);
  w.ground = dCreatePlane(nullptr, 0, 0, 1, 0);
  w.contacts = dJointGroupCreate(0);
  for (std::size_t k = 0; k < w.config.obstacles.size(); ++k) {
    const ObstacleBox& b = w.config.obstacles[k];
    dGeomID g = dCreateBox(nullptr, b.size_m.x, b.size_m.y, b.size_m.z);
    dGeomSetPosition(g, b.center_m.x, b.center_m.y, b.center_m.z);
    dMatrix3 R;
    dRFromAxisAndAngle(R, 0, 0, 1, b.yaw_rad);
    dGeomSetRotation(g, R);
    w.obstacle_tags.push_back(std::make_unique<GeomTag>(GeomTag{GeomTag::kObstacle, k}));
    dGeomSetData(g, w.obstacle_tags.back().get());
    w.obstacle_geoms.push_back(g);
    std::array<dReal, 6> aabb{};
    dGeomGetAABB(g, aabb.data());
    w.obstacle_aabbs.push_back(aabb);
  }
  w.renderer = std::make_unique<GroundRenderer>(w.config);
  w.wind.Advance(0.0);
  w.wind_now = w.wind.wind_m_s();
  return std::unique_ptr<World>(new World(std::move(impl)));
}

namespace {

// The spawn's checks after its name: a usable airframe, above the ground, a known payload with
// room to hang. The payload (in spawn.airframe), or nullptr.
Result<const PayloadSpec*> CheckSpawn(const DroneSpawn& spawn) {
  const Airframe& af = spawn.airframe;
  if (af.rotors.empty() || af.rotors.size() > 8 || af.mass_kg <= 0) {
    return Error(ErrorCode::kInvalidArgument, "drone '" + spawn.name + "': airframe has no valid rotors/mass");
  }
  if (spawn.position_m.z < 0) {
    return Error(ErrorCode::kInvalidArgument, "drone '" + spawn.name + "': start position below the ground");
  }
  if (spawn.payload.empty()) return static_cast<const PayloadSpec*>(nullptr);
  auto found = af.FindPayload(spawn.payload);
  if (!found) return Error(ErrorCode::kInvalidArgument, "drone '" + spawn.name + "': " + found.error().message());
  const PayloadSpec* payload = *found;
  if (spawn.payload_attached) {
    const Vec3 origin = spawn.position_m + Vec3{0, 0, af.base_height_m};
    const Vec3 hook = origin + Rotate(Quat::FromYaw(spawn.yaw_rad), payload->hook_m);
    if (hook.z - payload->sling_length_m - payload->size_m.z / 2 < 0) {
      return Error(ErrorCode::kInvalidArgument,
                   "drone '" + spawn.name + "': too low to spawn with the " + payload->name +
                       " hanging (needs the hook " + std::to_string(payload->sling_length_m + payload->size_m.z / 2) +
                       " m above the ground)");
    }
  }
  return payload;
}

}  // namespace

std::unique_ptr<World::Impl::Drone> World::Impl::NewDrone(const DroneSpawn& spawn, const PayloadSpec* payload,
                                                          std::size_t index) {
  const Airframe& af = spawn.airframe;
  auto d = std::make_unique<Drone>();
  d->name = spawn.name;
  d->af = af;
  d->rotor_count = af.rotors.size();
  d->alpha_up = 1.0 - std::exp(-dt_s / af.motor.time_constant_up_s);
  d->alpha_down = 1.0 - std::exp(-dt_s / af.motor.time_constant_down_s);
  const double throttle = std::clamp(spawn.initial_throttle, 0.0, 1.0);
  for (std::size_t r = 0; r < d->rotor_count; ++r) {
    d->u[r] = throttle;
    d->omega[r] = throttle * af.motor.max_rot_velocity_rad_s;
  }
  const Vec3 origin = spawn.position_m + Vec3{0, 0, af.base_height_m};
  const Quat q = Quat::FromYaw(spawn.yaw_rad);
  d->body = dBodyCreate(world);
  dMass m;
  dMassSetParameters(&m, af.mass_kg, 0, 0, 0, af.inertia_kg_m2.x, af.inertia_kg_m2.y, af.inertia_kg_m2.z, 0, 0, 0);
  dBodySetMass(d->body, &m);
  dBodySetPosition(d->body, origin.x, origin.y, origin.z);
  const dQuaternion dq = {q.w, q.x, q.y, q.z};
  dBodySetQuaternion(d->body, dq);
  dBodySetAutoDisableFlag(d->body, 0);
  d->geom = dCreateBox(nullptr, af.collision_box_m.x, af.collision_box_m.y, af.collision_box_m.z);
  dGeomSetBody(d->geom, d->body);
  dGeomSetOffsetPosition(d->geom, af.collision_offset_m.x, af.collision_offset_m.y, af.collision_offset_m.z);
  d->tag = std::make_unique<GeomTag>(GeomTag{GeomTag::kDrone, index});
  dGeomSetData(d->geom, d->tag.get());
  if (payload) {
    // The drone's own copy of the airframe holds the payload it carries.
    d->payload = &d->af.payloads[static_cast<std::size_t>(payload - af.payloads.data())];
    AddPayloadBody(*d, spawn, index);
  }
  d->sensors = std::make_unique<SensorSuite>(d->af, config, MixSeed(options.seed, 0x5E0000 + index));
  return d;
}

void World::Impl::AddPayloadBody(Drone& d, const DroneSpawn& spawn, std::size_t index) {
  const PayloadSpec& payload = *d.payload;
  const Vec3 origin = spawn.position_m + Vec3{0, 0, d.af.base_height_m};
  const Quat q = Quat::FromYaw(spawn.yaw_rad);
  const dQuaternion dq = {q.w, q.x, q.y, q.z};
  d.payload_body = dBodyCreate(world);
  dMass pm;
  dMassSetBoxTotal(&pm, payload.mass_kg, payload.size_m.x, payload.size_m.y, payload.size_m.z);
  dBodySetMass(d.payload_body, &pm);
  dBodySetAutoDisableFlag(d.payload_body, 0);
  Vec3 at;
  if (spawn.payload_attached) {
    at = origin + Rotate(q, payload.hook_m) - Vec3{0, 0, payload.sling_length_m};
  } else {
    const airframe::GroundPlacement g = airframe::PayloadOnGround(d.af, payload);
    at = Vec3{spawn.position_m.x + g.offset_x_m, spawn.position_m.y + g.offset_y_m, g.half_height_m};
  }
  dBodySetPosition(d.payload_body, at.x, at.y, at.z);
  dBodySetQuaternion(d.payload_body, dq);
  d.payload_geom = dCreateBox(nullptr, payload.size_m.x, payload.size_m.y, payload.size_m.z);
  dGeomSetBody(d.payload_geom, d.payload_body);
  d.payload_tag = std::make_unique<GeomTag>(GeomTag{GeomTag::kPayload, index});
  dGeomSetData(d.payload_geom, d.payload_tag.get());
  d.payload_drag = 0.5 * config.air_density_kg_m3 * 1.0 * payload.size_m.x * payload.size_m.y;
}

void World::Impl::AttachSling(Drone& d, const DroneSpawn& spawn) {
  const Vec3 origin = spawn.position_m + Vec3{0, 0, d.af.base_height_m};
  const Vec3 hook = origin + Rotate(Quat::FromYaw(spawn.yaw_rad), d.payload->hook_m);
  d.sling = dJointCreateBall(world, nullptr);
  dJointAttach(d.sling, d.body, d.payload_body);
  dJointSetBallAnchor(d.sling, hook.x, hook.y, hook.z);
}

void World::Impl::GrowBroadPhase(const Drone& added) {
  // Broad-phase slots for the new geoms (allocation happens here, not in Step()).
  const std::size_t geoms = bounds.size() + (added.payload_geom ? 2 : 1);
  bounds.resize(geoms);
  order.clear();
  for (std::size_t k = 0; k < geoms; ++k) order.push_back(static_cast<std::uint32_t>(k));
}

Result<std::size_t> World::AddDrone(const DroneSpawn& spawn) {
  Impl& w = *impl_;
  if (spawn.name.empty()) return Error(ErrorCode::kInvalidArgument, "drone name is empty");
  if (FindDrone(spawn.name)) return Error(ErrorCode::kAlreadyExists, "duplicate drone name '" + spawn.name + "'");
  auto payload = CheckSpawn(spawn);
  if (!payload) return payload.error();
  const std::size_t index = w.drones.size();
  auto d = w.NewDrone(spawn, *payload, index);
  w.index_of.emplace(d->name, w.drones.size());
  w.drones.push_back(std::move(d));
  Impl::Drone& added = *w.drones.back();
  if (*payload && spawn.payload_attached) w.AttachSling(added, spawn);
  added.prev_velocity = V(dBodyGetLinearVel(added.body));
  w.GrowBroadPhase(added);
  w.SampleSensors(added);
  return index;
}

std::size_t World::drone_count() const { return impl_->drones.size(); }
const std::string& World::drone_name(std::size_t i) const { return impl_->drones.at(i)->name; }
std::optional<std::size_t> World::FindDrone(std::string_view name) const {
  // Once per actuator answer: a hash lookup, not a scan of every drone (O(N^2) per step at 100).
  const auto it = impl_->index_of.find(name);
  if (it == impl_->index_of.end()) return std::nullopt;
  return it->second;
}
const PayloadSpec* World::payload(std::size_t index) const { return impl_->drones.at(index)->payload; }

const Airframe& World::airframe(std::size_t i) const { return impl_->drones.at(i)->af; }
const WorldConfig& World::config() const { return impl_->config; }
const WorldOptions& World::options() const { return impl_->options; }

Status World::SetActuators(std::size_t index, std::span<const double> u) {
  if (index >= impl_->drones.size()) return Error(ErrorCode::kNotFound, "no drone with index " + std::to_string(index));
  Impl::Drone& d = *impl_->drones[index];
  if (u.size() != d.rotor_count) {
    return Error(ErrorCode::kInvalidArgument, "drone '" + d.name + "' has " + std::to_string(d.rotor_count) +
                                                  " rotors, got " + std::to_string(u.size()) + " actuator values");
  }
  for (double v : u) {
    if (std::isnan(v)) return Error(ErrorCode::kInvalidArgument, "drone '" + d.name + "': NaN actuator value");
  }
  if (d.crashed || d.lost) return Ok{};
  for (std::size_t r = 0; r < d.rotor_count; ++r) d.u[r] = std::clamp(u[r], 0.0, 1.0);
  return Ok{};
}

void World::Step() {
  Impl& w = *impl_;
  const double period_s = static_cast<double>(w.options.control_period_ns) * 1e-9;
  w.wind.Advance(period_s);
  w.wind_now = w.wind.wind_m_s();
  const std::int64_t sub_ns = w.options.control_period_ns / w.options.substeps;
  for (int s = 0; s < w.options.substeps; ++s) {
    w.SubStep();
    w.time_ns += sub_ns;
  }
  ++w.step;
  for (std::size_t i = 0; i < w.drones.size(); ++i) {
    Impl::Drone& d = *w.drones[i];
    const Vec3 v = V(dBodyGetLinearVel(d.body));
    d.accel_world = (v - d.prev_velocity) * (1.0 / period_s);
    d.prev_velocity = v;
    const Vec3 p = V(dBodyGetPosition(d.body));
    const bool outside = std::abs(p.x) > w.config.size_x_m / 2 || std::abs(p.y) > w.config.size_y_m / 2;
    if (outside && !d.outside_geofence) w.Emit(EventKind::kGeofence, i, 0, 0.0);
    d.outside_geofence = outside;
    w.WatchPayload(d, i);
    w.SampleSensors(d);
  }
  w.Dispatch();
}

std::int64_t World::time_ns() const { return impl_->time_ns; }
double World::time_s() const { return static_cast<double>(impl_->time_ns) * 1e-9; }
std::uint64_t World::step_count() const { return impl_->step; }

const SensorSample& World::sensors(std::size_t index) const { return impl_->drones.at(index)->sample; }

DroneTruth World::Truth(std::size_t index) const {
  const Impl::Drone& d = *impl_->drones.at(index);
  const TrueKinematics k = impl_->Kinematics(d);
  DroneTruth t;
  t.position_m = k.position_m;
  t.velocity_m_s = k.velocity_m_s;
  t.attitude = k.attitude;
  t.body_rates_rad_s = k.body_rates_rad_s;
  t.accel_m_s2 = d.accel_world;
  t.rotor_count = static_cast<int>(d.rotor_count);
  for (std::size_t r = 0; r < d.rotor_count; ++r) t.rotor_speed_rad_s[r] = d.omega[r];
  t.payload_attached = d.sling != nullptr;
  t.payload_swing_rad = impl_->SwingAngle(d);
  if (d.payload_body) {
    t.payload_position_m = V(dBodyGetPosition(d.payload_body));
    const dReal* q = dBodyGetQuaternion(d.payload_body);
    t.payload_attitude = Quat{q[0], q[1], q[2], q[3]};
    dMass pm;
    dBodyGetMass(d.payload_body, &pm);
    t.payload_mass_kg = pm.mass;
  }
  t.crashed = d.crashed;
  t.lost = d.lost;
  return t;
}

Status World::AttachPayload(std::size_t index, double mass_kg) {
  Impl& w = *impl_;
  if (index >= w.drones.size()) return Error(ErrorCode::kNotFound, "no drone with index " + std::to_string(index));
  Impl::Drone& d = *w.drones[index];
  if (d.payload == nullptr) return Error(ErrorCode::kInvalidArgument, "drone '" + d.name + "' has no payload");
  if (!(mass_kg >= 0.0) || !std::isfinite(mass_kg)) {
    return Error(ErrorCode::kInvalidArgument, "drone '" + d.name + "': payload mass must be >= 0 kg (0 keeps it)");
  }
  if (d.sling) return Error(ErrorCode::kAlreadyExists, "drone '" + d.name + "': " + d.payload->name + " already attached");
  const Vec3 hook = V(dBodyGetPosition(d.body)) + RotR(dBodyGetRotation(d.body), d.payload->hook_m);
  const double dist = Norm(V(dBodyGetPosition(d.payload_body)) - hook);
  if (std::abs(dist - d.payload->sling_length_m) > d.payload->attach_tolerance_m) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "hook is %.2f m from the %s, needs %.2f +- %.2f m", dist, d.payload->name.c_str(),
                  d.payload->sling_length_m, d.payload->attach_tolerance_m);
    return Error(ErrorCode::kInvalidArgument, "drone '" + d.name + "': " + buf);
  }
  if (mass_kg > 0.0) {  // what was loaded onto it: same box, new mass
    dMass pm;
    dMassSetBoxTotal(&pm, mass_kg, d.payload->size_m.x, d.payload->size_m.y, d.payload->size_m.z);
    dBodySetMass(d.payload_body, &pm);
  }
  d.sling = dJointCreateBall(w.world, nullptr);
  dJointAttach(d.sling, d.body, d.payload_body);
  dJointSetBallAnchor(d.sling, hook.x, hook.y, hook.z);
  d.payload_settling = false;  // picked up again before it settled: nothing to report
  w.Emit(EventKind::kPayloadAttached, index, 0, 0.0);
  w.Dispatch();
  return Ok{};
}

Status World::ReleasePayload(std::size_t index) {
  Impl& w = *impl_;
  if (index >= w.drones.size()) return Error(ErrorCode::kNotFound, "no drone with index " + std::to_string(index));
  Impl::Drone& d = *w.drones[index];
  if (d.sling == nullptr) return Error(ErrorCode::kInvalidArgument, "drone '" + d.name + "' carries no attached payload");
  dJointDestroy(d.sling);
  d.sling = nullptr;
  d.payload_settling = true;
  d.payload_still_ns = -1;
  w.Emit(EventKind::kPayloadReleased, index, 0, 0.0);
  w.Dispatch();
  return Ok{};
}

void World::SetGpsDropout(std::size_t index, bool dropped_out) { impl_->drones.at(index)->gps_dropout = dropped_out; }

void World::SetGpsAccuracy(std::size_t index, double horizontal_std_m, double vertical_std_m) {
  impl_->drones.at(index)->sensors->SetGpsAccuracy(horizontal_std_m, vertical_std_m);
}

void World::AddImuBias(std::size_t index, const Vec3& accel_m_s2, const Vec3& gyro_rad_s) {
  impl_->drones.at(index)->sensors->AddImuBias(accel_m_s2, gyro_rad_s);
}

void World::SetWind(const WindConfig& wind) {
  impl_->wind.Configure(wind);
  impl_->wind_now = impl_->wind.wind_m_s();
}
Vec3 World::wind_m_s() const { return impl_->wind_now; }

void World::SetLost(std::size_t index, bool lost) {
  Impl& w = *impl_;
  Impl::Drone& d = *w.drones.at(index);
  if (d.lost == lost) return;
  d.lost = lost;
  if (lost) d.u.fill(0.0);
  w.Emit(lost ? EventKind::kDroneLost : EventKind::kDroneRejoined, index, 0, 0.0);
  w.Dispatch();
}

void World::SetOut(std::size_t index, bool out) {
  Impl::Drone& d = *impl_->drones.at(index);
  d.lost = out;
  if (out) d.u.fill(0.0);
}

void World::SetExternalForce(std::size_t index, const Vec3& force_n) { impl_->drones.at(index)->external_force = force_n; }

void World::SetPinned(std::size_t index, bool pinned) {
  Impl& w = *impl_;
  Impl::Drone& d = *w.drones.at(index);
  if (pinned == (d.pin != nullptr)) return;
  if (pinned) {
    d.pin = dJointCreateFixed(w.world, nullptr);
    dJointAttach(d.pin, d.body, nullptr);
    dJointSetFixed(d.pin);
  } else {
    dJointDestroy(d.pin);
    d.pin = nullptr;
  }
}

void World::RenderCamera(std::size_t index, CameraImage* out, std::vector<VisiblePerson>* people) {
  Impl& w = *impl_;
  const Impl::Drone& d = *w.drones.at(index);
  const TrueKinematics k = w.Kinematics(d);
  w.renderer->Render(Pose{k.position_m, k.attitude}, k.body_rates_rad_s, d.af.camera,
                     MixSeed(w.options.seed, (static_cast<std::uint64_t>(index) << 40) ^ w.step), out, people);
  out->time_ns = w.time_ns;
}

Status World::RenderThermal(std::size_t index, ThermalImage* out, std::vector<VisiblePerson>* people) {
  Impl& w = *impl_;
  const Impl::Drone& d = *w.drones.at(index);
  if (!d.af.thermal.enabled) {
    return Error(ErrorCode::kInvalidArgument,
                 "drone " + std::to_string(index) + " carries no thermal camera");
  }
  if (!w.thermal) w.thermal = std::make_unique<ThermalRenderer>(w.config);
  const TrueKinematics k = w.Kinematics(d);
  w.thermal->Render(Pose{k.position_m, k.attitude}, d.af.thermal,
                    MixSeed(w.options.seed ^ 0x7E4A11ULL, (static_cast<std::uint64_t>(index) << 40) ^ w.step),
                    out, people);
  out->time_ns = w.time_ns;
  return Ok{};
}

bool World::CameraDue(std::size_t index) const {
  const Impl& w = *impl_;
  const double rate = w.drones.at(index)->af.camera.rate_hz;
  const double steps = 1e9 / (rate * static_cast<double>(w.options.control_period_ns));
  const auto every = static_cast<std::uint64_t>(std::max(1.0, std::round(steps)));
  return w.step % every == 0;
}

void World::SetEventSink(EventSink* sink) { impl_->sink = sink; }

}  // namespace swarmbox::physics
