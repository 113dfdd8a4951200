// The agent's built-in flight plan, and the interface any setpoint source (the mission layer,
// flocking) implements to drive the flight controller.
//
//   auto plan = FlightPlan::Parse("takeoff:5,hover:10,goto:10:0:5,land");   // Result<FlightPlan>
//   each control step:  if (auto sp = plan->Tick(status)) controller.Command(*sp);
//
// Steps: takeoff:H (climb H metres above the start; waits for `hover`), hover:S (hold S seconds),
// goto:X:Y:Z[:YAW_DEG] (fly to the world ENU point; waits for `arrived`), velocity:VX:VY:VZ:S
// (follow the velocity for S seconds, then hold), land (waits for `landed`). Time is simulated.
// Pure: no I/O, no clock.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/flight/setpoint.hpp"
#include "swarmbox/flight/types.hpp"

namespace swarmbox::agent {

// What a setpoint source sees of the flight controller at one step.
struct FlightStatus {
  double t_s = 0.0;                                    // simulated time [s]
  flight::FlightMode mode = flight::FlightMode::kInit;
  flight::Vec3 pos_m = flight::Vec3::Zero();           // estimated position, world ENU
  bool arrived = false;                                // events seen at this step
  bool hover = false;
  bool landed = false;
  bool rejected = false;
};

// Upper layers (mission, flocking, this plan) implement this; the agent calls Tick() once per
// control step and forwards the returned setpoint to FlightController::Command().
class SetpointSource {
 public:
  virtual ~SetpointSource() = default;
  virtual std::optional<flight::Setpoint> Tick(const FlightStatus& status) = 0;
  virtual bool finished() const = 0;
  // A short description of what it is doing now, for logs ("takeoff:5", "hover:10"...).
  virtual std::string_view current() const = 0;
};

class FlightPlan final : public SetpointSource {
 public:
  struct Step {
    enum class Kind { kTakeoff, kHover, kGoto, kVelocity, kLand };
    Kind kind = Kind::kHover;
    flight::Vec3 value = flight::Vec3::Zero();
    double yaw_rad = 0.0;    // NaN: keep heading
    double duration_s = 0.0;
    std::string text;        // as written
  };

  // kInvalidArgument naming the bad step and the accepted forms.
  static Result<FlightPlan> Parse(std::string_view text);

  // preflight_s: how long to wait on the ground after the controller is ready before take-off
  // (the estimator learns its biases meanwhile).
  void SetPreflight(double preflight_s) { preflight_s_ = preflight_s; }

  std::optional<flight::Setpoint> Tick(const FlightStatus& status) override;
  bool finished() const override { return index_ >= steps_.size(); }
  std::string_view current() const override;
  // Index of the step running now; a change since the last call means a new step started.
  std::size_t index() const { return index_; }
  const std::vector<Step>& steps() const { return steps_; }

 private:
  // A take-off waits on the ground for the preflight time; every other step starts at once.
  bool ReadyToStart(const Step& step, const FlightStatus& status);
  // The started step is done (or refused); `out`: a setpoint to end it with (a velocity leg holds).
  bool StepDone(const Step& step, const FlightStatus& status, std::optional<flight::Setpoint>* out) const;

  std::vector<Step> steps_;
  std::size_t index_ = 0;
  bool started_ = false;       // the current step's setpoint was sent
  double step_start_s_ = 0.0;
  double ready_since_s_ = -1.0;
  double preflight_s_ = 2.0;
};

}  // namespace swarmbox::agent
