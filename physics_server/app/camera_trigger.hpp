// CameraTrigger: when a drone's downward camera takes its next frame, as a survey drone's
// autopilot triggers its camera (PX4's camera_trigger driver, TRIG_MODE 3 "distance based": "a
// shot is taken every time the set horizontal distance is exceeded; the minimum time interval
// between two shots is however limited by the set triggering interval", TRIG_DISTANCE and
// TRIG_INTERVAL; docs.px4.io/v1.14/en/peripherals/camera).
//
//   CameraTrigger trigger(drone_count);
//   if (trigger.Due(i, spec, rate_due, t_ns, position_m)) { render; trigger.Captured(i, t_ns, position_m); }
//
// With spec.trigger_distance_m = 0 it is the fixed rate: every step `rate_due` says (the
// World::CameraDue grid of rate_hz). With a distance, a frame is due on that grid (rate_hz is the
// upper bound, PX4's minimum interval) once the camera has moved trigger_distance_m horizontally
// since the drone's last frame, or trigger_interval_max_s has passed since it (a hovering, climbing
// or holding drone still looks now and then; PX4 has no such floor, it is this project's choice
// for the mission's revisits, which hover over a spot and look), and always for a drone's first
// frame. Pure: simulated time and the drone's true position in, no clock; the same run gives the
// same frames. (PX4 measures from the estimated position; the server has only the truth, which
// the estimate tracks within its GPS error, well under the distances used here.)
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "swarmbox/airframe/airframe.hpp"
#include "swarmbox/physics/world.hpp"

namespace swarmbox::physics {

class CameraTrigger {
 public:
  explicit CameraTrigger(std::size_t drones) : last_(drones) {}

  // Whether drone `drone`'s camera takes a frame at simulated time `t_ns` with its body at
  // `position_m` (world ENU). `rate_due`: this step is on the rate_hz grid.
  bool Due(std::size_t drone, const airframe::CameraSpec& spec, bool rate_due, std::int64_t t_ns,
           const Vec3& position_m) const;
  // Records a frame taken (call after each frame Due allowed).
  void Captured(std::size_t drone, std::int64_t t_ns, const Vec3& position_m);

 private:
  struct Last {
    bool taken = false;
    std::int64_t t_ns = 0;
    double x_m = 0, y_m = 0;
  };
  std::vector<Last> last_;
};

}  // namespace swarmbox::physics
