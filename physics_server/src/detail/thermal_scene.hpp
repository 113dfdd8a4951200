// The thermal camera's world (ThermalRenderer): the RGB scene's geometry with each surface's
// apparent temperature [K] in place of its colour, and the ground texture as a CV_32F map of
// temperatures. Each surface is in a steady state with the sunlight it absorbs and, for a person,
// the body's warmth that reaches it (physics_server/README.md "Thermal" has the figures):
//
//   T = T_air + a * E / h + pass * (T_skin - T_air) - C / h
//
//   E     sunlight on the surface [W/m^2]: the sun's on a horizontal surface (none in a shadow)
//         plus the sky's (Light::direct, Light::ambient of the world's `lighting`)
//   a     its absorptance of sunlight: 1 - 0.9 x its visible luma / 255 (dark absorbs)
//   h     the heat it gives off per kelvin over the air [W/m^2/K], by kind (Heat): convection
//         and radiation, and what a solid conducts into the ground, or a leaf transpires
//   pass  the share of the body's warmth over the air its surface shows: 1 for the skin, the
//         clothing's (kClothingPass, by victim), 0.5 for hair, 0 for anything not alive
//   C     the net long-wave loss to a clear sky [W/m^2] (less under cloud)
// Water stays kWaterBelowAirK under the air (evaporation, its heat capacity).
// Pure: the same scene and world give the same temperatures.
#pragma once

#include <array>

#include <opencv2/core.hpp>

#include "detail/render_scene.hpp"
#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::physics::detail {

// The share of the body's warmth over the air left at the clothing's surface: one minus the
// reduction of the surface temperature against the forehead's measured through fleece (72.6 %),
// fleece and a down jacket (82.2 %), and those and an all-weather jacket (92.3 %) (Rescue
// blankets hamper thermal imaging in search and rescue missions, 2020).
inline constexpr std::array<double, 3> kClothingPass = {0.274, 0.178, 0.077};
inline constexpr double kSkinK = 306.15;        // 33 deg C, the skin an LWIR camera sees (assumption)
inline constexpr double kWaterBelowAirK = 1.5;  // assumption

// What warms and cools the surfaces of one world.
struct ThermalEnv {
  double air_k = 293.15;
  double sun_w_m2 = 0;      // the sun's irradiance on a horizontal surface
  double sky_w_m2 = 0;      // the sky's (diffuse)
  double cooling_w_m2 = 0;  // net long-wave loss to the sky (C above)
  double sky_k = 253.15;    // the sky's apparent temperature (seen only by a tilted camera)
};
ThermalEnv ThermalEnvOf(const WorldConfig& config, const Light& light);

// A surface's temperature [K]: its kind, visible colour (BGR), the share of the sun's direct
// light on it (0 in a shadow), and for clothing the share of the body's warmth it shows.
double SurfaceK(Heat heat, const cv::Scalar& bgr, double sunlit, const ThermalEnv& env, double clothing_pass);

// The scene in kelvin: the RGB scene's texture and parts, each at its temperature. `rgb` must
// come from BuildScene (with its vegetation, wet and shadow maps).
RenderScene ThermalSceneOf(const RenderScene& rgb, const WorldConfig& config);

}  // namespace swarmbox::physics::detail
