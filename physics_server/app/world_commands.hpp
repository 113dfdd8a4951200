// The world commands this physics server takes on sim/world_command (bus WorldCommand {target,
// command, args}), as one table: SimServer checks what arrives against it, and the one-shot sender
// (`swarmbox-physics --send-command`, command_sender.hpp) refuses a bad command before it joins
// the bus. Units: durations [s], accuracies [m], accelerations [m/s^2], rates [rad/s], wind [m/s]
// (ENU world frame).
//
//   gps_dropout   <drone> duration_s                      no fixes for duration_s, then back
//   gps_degrade   <drone> duration_s h_acc_m v_acc_m      worse fixes for duration_s, then back
//   imu_bias_jump <drone> ax ay az gx gy gz               added to the IMU biases (no undo: send
//                                                         the negated jump to take it back)
//   wind_gust     -       vx vy vz duration_s             added to the mean wind, then back
//   payload_attach / payload_release <drone> [args...]   the lifter's hook (args not checked)
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::physics {

struct WorldCommandSpec {
  std::string_view name;
  bool needs_drone = false;     // false: the whole world (target "")
  int arg_count = 0;            // -1: any number, not checked
  unsigned positive_args = 0;   // bit i set: args[i] must be > 0
  std::string_view usage;       // the reject reason / usage text: "needs a drone and duration_s > 0"
};

// Every command, in the order above.
std::span<const WorldCommandSpec> WorldCommandSpecs();
// nullptr for an unknown name.
const WorldCommandSpec* FindWorldCommand(std::string_view name);
// Checks a command against the table: kInvalidArgument whose message is the reject reason ("not
// supported by this physics server", or the command's usage). Whether the drone exists is the
// server's business.
Status CheckWorldCommand(std::string_view command, bool has_target, const std::vector<double>& args);

}  // namespace swarmbox::physics
