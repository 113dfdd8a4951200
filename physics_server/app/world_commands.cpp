#include "world_commands.hpp"

#include <array>

namespace swarmbox::physics {

namespace {

constexpr std::array<WorldCommandSpec, 6> kSpecs{{
    {"gps_dropout", true, 1, 0b1, "needs a drone and duration_s > 0"},
    {"gps_degrade", true, 3, 0b111, "needs a drone, duration_s, h_acc_m, v_acc_m > 0"},
    {"imu_bias_jump", true, 6, 0, "needs a drone and ax, ay, az, gx, gy, gz"},
    {"wind_gust", false, 4, 0b1000, "needs vx, vy, vz, duration_s > 0"},
    {"payload_attach", true, -1, 0, "needs a drone (and at most mass_kg)"},
    {"payload_release", true, -1, 0, "needs a drone"},
}};

}  // namespace

std::span<const WorldCommandSpec> WorldCommandSpecs() { return kSpecs; }

const WorldCommandSpec* FindWorldCommand(std::string_view name) {
  for (const WorldCommandSpec& s : kSpecs) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

Status CheckWorldCommand(std::string_view command, bool has_target, const std::vector<double>& args) {
  const WorldCommandSpec* spec = FindWorldCommand(command);
  if (spec == nullptr) return Error(ErrorCode::kInvalidArgument, "not supported by this physics server");
  bool ok = !spec->needs_drone || has_target;
  if (spec->arg_count >= 0) ok = ok && args.size() == static_cast<std::size_t>(spec->arg_count);
  for (std::size_t i = 0; ok && i < args.size() && i < 32; ++i) {
    if ((spec->positive_args >> i) & 1u) ok = args[i] > 0;
  }
  if (!ok) return Error(ErrorCode::kInvalidArgument, std::string(spec->usage));
  return Ok{};
}

}  // namespace swarmbox::physics
