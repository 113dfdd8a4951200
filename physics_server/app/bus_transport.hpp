// BusTransport: SimTransport on the SwarmBox sim bus (bus/topics.hpp): per drone a SensorSample
// and CameraImage publisher and an ActuatorCommand subscriber, plus the clock publisher and the
// world-command subscriber. Actuator commands arrive on middleware threads and are queued here.
//
// Sensor mapping (physics SensorSample -> bus SensorSample): each sensor's `valid` means "a new
// measurement at this step" (the physics `fresh` flag; stale values are repeated but invalid).
// GPS: valid = a new fix; fix_type = kNone in a dropout (reports keep coming at the GPS rate with
// valid = false), k3d otherwise. Baro altitude is relative to the world origin (ENU z).
// camera_frame and radio_in come from SampleExtras. An ActuatorCommand's world commands keep
// their seq (SimServer orders them); the `drone` fields of the message are not trusted (the topic
// names the drone).
#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "sim_server.hpp"
#include "swarmbox/bus/participant.hpp"
#include "swarmbox/physics/airframe.hpp"

namespace swarmbox::physics {

class BusTransport final : public SimTransport {
 public:
  // Creates the participant and every drone's endpoints. `airframes[i]` gives drone i's GPS spec
  // (accuracy fields).
  static Result<std::unique_ptr<BusTransport>> Create(const bus::ParticipantConfig& config,
                                                      const std::vector<std::string>& drones,
                                                      const std::vector<GpsSpec>& gps_specs);

  Status PublishSample(std::size_t drone, const std::string& name, const SensorSample& sample,
                       const SampleExtras& extras) override;
  Status PublishCamera(std::size_t drone, const std::string& name, std::uint64_t step, const CameraImage& image) override;
  Status PublishClock(std::uint64_t step, std::int64_t sim_time_ns, std::int64_t period_ns, double rtf) override;
  Status PublishStatus(const JoiningStatus& status, bool done) override;
  void WaitActuators(std::int64_t deadline_ns, std::vector<ActuatorInput>* out) override;
  void TakeWorldCommands(std::vector<WorldCommandInput>* out) override;

 private:
  BusTransport() = default;
  struct DroneEndpoints {
    std::unique_ptr<bus::Publisher<bus::SensorSample>> sensor;
    std::unique_ptr<bus::Publisher<bus::CameraImage>> camera;
    std::unique_ptr<bus::Subscriber<bus::ActuatorCommand>> actuator;
    GpsSpec gps;
  };
  std::unique_ptr<bus::Participant> participant_;
  std::unique_ptr<bus::Publisher<bus::ClockTick>> clock_;
  std::unique_ptr<bus::Publisher<bus::Event>> status_;  // sim/status
  std::unique_ptr<bus::Subscriber<bus::WorldCommand>> world_commands_;
  std::vector<DroneEndpoints> drones_;
  bus::SensorSample sample_msg_;
  bus::CameraImage camera_msg_;

  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<ActuatorInput> actuators_;
  std::deque<WorldCommandInput> world_;
};

}  // namespace swarmbox::physics
