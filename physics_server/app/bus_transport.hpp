// BusTransport: SimTransport on the SwarmBox sim bus (bus/topics.hpp): per drone a SensorSample
// and CameraImage publisher, and a stereo pair publisher (StereoTopic) for a drone whose airframe
// has stereo enabled (none otherwise: no endpoint for nothing); one ActuatorCommand subscriber on sim/actuator for every drone (keyed
// by drone); the clock publisher and the world-command subscriber. Actuator commands arrive on a
// middleware thread (one callback call at a time), are matched to their drone by name in O(1) and
// queued here; the server's thread is woken once the step's awaited answers are queued (or at its
// deadline), not once per answer.
// The physics server's start progress goes out on sim/status (PublishStatus).
//
// Sensor mapping (physics SensorSample -> bus SensorSample): each sensor's `valid` means "a new
// measurement at this step" (the physics `fresh` flag; stale values are repeated but invalid).
// GPS: valid = a new fix; fix_type = kNone in a dropout (reports keep coming at the GPS rate with
// valid = false), k3d otherwise. Baro altitude is relative to the world origin (ENU z).
// camera_frame, stereo_frame and radio_in come from SampleExtras. An ActuatorCommand's world commands keep
// their seq (SimServer orders them). The command's key (`drone`) names the answering drone; a
// command for a drone not in the trial is dropped and counted (unknown_commands()).
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "sim_server.hpp"
#include "swarmbox/bus/participant.hpp"
#include "swarmbox/physics/airframe.hpp"

namespace swarmbox::physics {

class BusTransport final : public SimTransport {
 public:
  // Creates the participant and every drone's endpoints. `airframes[i]` gives drone i's GPS spec
  // (accuracy fields); `stereo_drones[i]` (absent: false) whether drone i publishes stereo pairs.
  static Result<std::unique_ptr<BusTransport>> Create(const bus::ParticipantConfig& config,
                                                      const std::vector<std::string>& drones,
                                                      const std::vector<GpsSpec>& gps_specs,
                                                      const std::vector<bool>& stereo_drones = {});

  Status PublishSample(std::size_t drone, const std::string& name, const SensorSample& sample,
                       const SampleExtras& extras) override;
  Status PublishCamera(std::size_t drone, const std::string& name, std::uint64_t step, const CameraImage& image) override;
  // kInternal for a drone created without a stereo publisher (a bug: SimServer sends none).
  Status PublishStereo(std::size_t drone, const bus::CameraImage& pair) override;
  Status PublishThermal(std::size_t drone, const std::string& name, std::uint64_t step,
                        const ThermalImage& image) override;
  Status PublishClock(std::uint64_t step, std::int64_t sim_time_ns, std::int64_t period_ns, double rtf) override;
  Status PublishStatus(const JoiningStatus& status, bool done) override;
  void WaitActuators(std::int64_t deadline_ns, std::size_t awaited, std::vector<ActuatorInput>* out) override;
  void TakeWorldCommands(std::vector<WorldCommandInput>* out) override;

  // The agents' telemetry for the recording (sim/telemetry, every agent on one keyed reader):
  // each sample is handed to `on_telemetry` on a middleware thread. Once; before the agents start.
  Status SubscribeTelemetry(std::function<void(const bus::Telemetry&)> on_telemetry);

  // Actuator commands whose `drone` is not a drone of the trial (dropped).
  std::uint64_t unknown_commands() const;

 private:
  BusTransport() = default;
  struct DroneEndpoints {
    std::string name;
    std::unique_ptr<bus::Publisher<bus::SensorSample>> sensor;
    std::unique_ptr<bus::Publisher<bus::CameraImage>> camera;
    std::unique_ptr<bus::Publisher<bus::CameraImage>> stereo;  // null: no stereo pair
    GpsSpec gps;
  };
  struct NameHash {
    using is_transparent = void;
    std::size_t operator()(std::string_view s) const { return std::hash<std::string_view>{}(s); }
  };
  void OnActuator(const bus::ActuatorCommand& c);
  // Create's steps, in discovery order: the clock, status and world-command endpoints, then each
  // drone's sensor and camera publishers.
  Status OpenWorldEndpoints();
  Status AddDroneEndpoints(const std::string& name, const GpsSpec& gps, bool stereo, std::size_t index);

  std::unique_ptr<bus::Participant> participant_;
  std::unique_ptr<bus::Publisher<bus::ClockTick>> clock_;
  std::unique_ptr<bus::Publisher<bus::Event>> status_;  // sim/status
  std::vector<DroneEndpoints> drones_;
  std::unordered_map<std::string, std::size_t, NameHash, std::equal_to<>> index_of_;  // set before the subscriber
  bus::SensorSample sample_msg_;
  bus::CameraImage camera_msg_;
  bus::CameraImage thermal_msg_;

  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<ActuatorInput> actuators_;
  std::deque<WorldCommandInput> world_;
  std::size_t wake_at_ = 0;  // 0: nobody waits; else notify once actuators_ holds this many
  std::uint64_t unknown_ = 0;
  // Last: destroyed first, so no callback runs while the members above go away.
  std::unique_ptr<bus::Subscriber<bus::WorldCommand>> world_commands_;
  std::unique_ptr<bus::Subscriber<bus::ActuatorCommand>> actuators_sub_;
  std::unique_ptr<bus::Subscriber<bus::Telemetry>> telemetry_sub_;
};

}  // namespace swarmbox::physics
