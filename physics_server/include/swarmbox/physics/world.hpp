// World: the simulated world of one trial, in process. ODE rigid bodies: gravity, ground plane,
// static obstacle boxes, N multirotors (first-order motors, thrust and yaw torque ~ omega^2,
// rotor and body drag, seeded wind), slung payloads, contacts and events; per-drone sensors and a
// downward camera rendered on demand. Used by the swarmbox-physics server, by closed-loop tests of
// the flight stack and by the benchmarks.
//
//   auto world = World::Create(*LoadWorld("trials/worlds/open_field.yaml"), {.seed = 42});
//   auto x500 = LoadAirframe("trials/airframes/x500.yaml");
//   std::size_t d = *(*world)->AddDrone({.name = "scout_1", .airframe = *x500, .position_m = {0, 0, 0}});
//   std::vector<double> u(4, 0.6);
//   for (int k = 0; k < 250; ++k) {              // 1 s at 250 Hz
//     const SensorSample& s = (*world)->sensors(d);   // answer this step's sample...
//     (void)(*world)->SetActuators(d, u);        // ...with a command
//     (*world)->Step();                          // 4 ms: 4 ODE sub-steps of 1 ms
//   }
//
// Time: Step() advances one control step (options.control_period_ns, default 4 ms = 250 Hz) made
// of options.substeps ODE sub-steps (default 4: 1 kHz). sensors(i) is the sample at the current
// time (after the last Step(), or at t = 0), whose `step` field is the index of the step that the
// next Step() will run.
// Determinism: the same config, seed, drones and command sequence give bit-identical states.
// Threading: not thread-safe; one thread drives a World. Several Worlds may live in one process.
// Allocation: Step() does not allocate except when it hands events to the sink.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/physics/airframe.hpp"
#include "swarmbox/physics/camera_image.hpp"
#include "swarmbox/physics/events.hpp"
#include "swarmbox/physics/sensor_sample.hpp"
#include "swarmbox/physics/types.hpp"
#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::physics {

struct VisiblePerson;  // ground_renderer.hpp
struct ThermalImage;   // thermal_renderer.hpp

struct WorldOptions {
  std::uint64_t seed = 1;                        // drives every noise source and the wind
  std::int64_t control_period_ns = 4'000'000;    // one Step() [ns] (250 Hz)
  int substeps = 4;                              // ODE sub-steps per Step() (1 kHz)
};

struct DroneSpawn {
  std::string name;
  Airframe airframe;
  // Where the drone stands: the body origin is placed base_height_m above this point, so z = 0
  // means "landed on the ground" [m, ENU].
  Vec3 position_m;
  double yaw_rad = 0;                // ENU yaw (0: nose east)
  double initial_throttle = 0;       // rotors already spinning at u * max speed (airborne spawns)
  std::string payload;               // "" or one of airframe.payloads[].name
  // With a payload: true = hanging sling_length_m under the hook at spawn (needs the height),
  // false = lying on the ground beside the drone (to its south, ENU -y, clear of its collision
  // box), ready for AttachPayload() once the drone hovers above it.
  bool payload_attached = false;
};

class World {
 public:
  // Fails (kInvalidArgument) on a config that cannot be simulated (negative sizes, substeps < 1).
  static Result<std::unique_ptr<World>> Create(const WorldConfig& config, const WorldOptions& options);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // Adds a drone (allocates; do it before stepping). Errors: duplicate name, unknown payload,
  // spawn inside the ground, attached payload without room to hang. Returns the drone's index.
  Result<std::size_t> AddDrone(const DroneSpawn& spawn);

  std::size_t drone_count() const;
  const std::string& drone_name(std::size_t index) const;
  std::optional<std::size_t> FindDrone(std::string_view name) const;
  const Airframe& airframe(std::size_t index) const;
  // The payload the drone carries or has carried (its airframe's, named at spawn), or nullptr;
  // Truth() gives its pose.
  const PayloadSpec* payload(std::size_t index) const;
  const WorldConfig& config() const;
  const WorldOptions& options() const;

  // Actuator command, one value per rotor in the airframe's rotor order, each clamped to [0, 1];
  // held until the next call. Error (and no change) on a wrong count or a NaN. Ignored (motors
  // stay off) while the drone is lost or crashed.
  Status SetActuators(std::size_t index, std::span<const double> u);

  // Advances one control step. Events found during it go to the sink afterwards.
  void Step();

  std::int64_t time_ns() const;
  double time_s() const;
  std::uint64_t step_count() const;   // Step() calls so far

  const SensorSample& sensors(std::size_t index) const;
  DroneTruth Truth(std::size_t index) const;

  // Payloads. Attach: the drone's hook must be within sling_length_m +- attach_tolerance_m of the
  // payload's centre; the sling keeps the distance it has then. Errors say why not.
  // mass_kg > 0: the payload's mass from now on (what was loaded onto it, e.g. the 80 kg of
  // stretcher and evacuee), a uniform box of the payload's size; 0 keeps its current mass (the
  // airframe's at spawn). Negative or NaN: kInvalidArgument, nothing changes.
  Status AttachPayload(std::size_t index, double mass_kg = 0.0);
  Status ReleasePayload(std::size_t index);

  // Faults and lifecycle.
  void SetGpsDropout(std::size_t index, bool dropped_out);   // GPS reports no fix while set
  // GPS noise override (1-sigma, metres); a value <= 0 restores the airframe's.
  void SetGpsAccuracy(std::size_t index, double horizontal_std_m, double vertical_std_m);
  // Adds a step to the IMU biases (accelerometer [m/s^2], gyro [rad/s], body FLU).
  void AddImuBias(std::size_t index, const Vec3& accel_m_s2, const Vec3& gyro_rad_s);
  void SetWind(const WindConfig& wind);                      // e.g. a gust fault
  Vec3 wind_m_s() const;                                     // current wind (mean + gust) [m/s]
  // Lost drones (lockstep timeout) get motors off and event=drone_lost; clearing it emits
  // event=drone_rejoined and commands count again.
  void SetLost(std::size_t index, bool lost);
  // A drone taken out of the trial by a process fault (the server's radio plan: kill, stop,
  // pause, restart): motors off from now as when lost (Truth().lost is true), but no event (the
  // server logs event=drone_out / drone_back). Clearing it lets commands count again.
  void SetOut(std::size_t index, bool out);
  // Test rigs and disturbances: a force [N, world ENU] applied at the drone's centre of mass on
  // every sub-step until changed ({} clears it).
  void SetExternalForce(std::size_t index, const Vec3& force_n);
  // Test rigs: pins the drone's body to the world where it is (a fixed joint) or frees it.
  void SetPinned(std::size_t index, bool pinned);

  // Renders the drone's downward camera at its true pose and body rates now (GroundRenderer;
  // BENCHMARKS.md "Camera" has the cost per frame). `out` is resized as needed (reuse it to avoid
  // allocation). `people` (optional, ground truth for training and evaluation, never for agents)
  // receives the people the frame shows.
  void RenderCamera(std::size_t index, CameraImage* out, std::vector<VisiblePerson>* people = nullptr);
  // Whether a camera frame is due at the current step (camera.rate_hz of the airframe).
  bool CameraDue(std::size_t index) const;
  // Renders the drone's thermal camera (airframe `thermal:`, ThermalRenderer) at its true pose now;
  // the renderer is built on the first call (its scene costs as much as the RGB camera's).
  // kInvalidArgument: the drone's airframe has no thermal camera.
  Status RenderThermal(std::size_t index, ThermalImage* out, std::vector<VisiblePerson>* people = nullptr);

  // Not owned; nullptr drops events. Must outlive the World or be reset.
  void SetEventSink(EventSink* sink);

 private:
  struct Impl;
  explicit World(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmbox::physics
