#include "detail/thermal_scene.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::physics::detail {
namespace {

constexpr double kCelsius = 273.15;
// The sun's irradiance per unit of Light::direct (sin(elevation), less under cloud): 1000 W/m^2,
// a clear sky's direct normal irradiance at sea level, rounded (assumption).
constexpr double kSunW = 1000.0;
// The sky's per unit of Light::ambient in full daylight: 330 W/m^2, so a clear noon (ambient 0.3)
// gets 100 W/m^2 of diffuse light and an overcast one (0.55) 180 (assumption).
constexpr double kSkyW = 330.0;
// The net long-wave loss to a clear sky, 100 W/m^2; a full overcast keeps 10 % of it (assumption).
constexpr double kClearSkyLossW = 100.0;

// h [W/m^2/K] by kind (assumptions): a solid's convection and radiation (~15) and what it conducts
// into the ground beneath (~30); a thin sheet's convection and radiation alone; a leaf's with its
// transpiration; skin's with the blood flow that holds it near kSkinK.
double HeatLossW(Heat heat) {
  switch (heat) {
    case Heat::kSolid:
      return 45.0;
    case Heat::kSheet:
      return 25.0;
    case Heat::kVegetation:
      return 150.0;
    case Heat::kClothing:
      return 25.0;
    case Heat::kSkin:
      return 150.0;
    case Heat::kHair:
      return 25.0;
  }
  return 45.0;
}

double BodyPass(Heat heat, double clothing_pass) {
  switch (heat) {
    case Heat::kClothing:
      return clothing_pass;
    case Heat::kSkin:
      return 1.0;
    case Heat::kHair:
      return 0.5;
    default:
      return 0.0;
  }
}

double Absorptance(const cv::Scalar& bgr) {
  const double luma = 0.114 * bgr[0] + 0.587 * bgr[1] + 0.299 * bgr[2];
  return 1.0 - 0.9 * std::clamp(luma, 0.0, 255.0) / 255.0;
}

std::vector<Part> InKelvin(const std::vector<Part>& parts, const ThermalEnv& env, double clothing_pass) {
  std::vector<Part> out = parts;
  for (Part& p : out) p.colour = cv::Scalar(SurfaceK(p.heat, p.colour, 1.0, env, clothing_pass));
  return out;
}

}  // namespace

ThermalEnv ThermalEnvOf(const WorldConfig& config, const Light& light) {
  ThermalEnv env;
  const double air_c = config.lighting ? config.lighting->air_temperature_c : 20.0;
  const double overcast = config.lighting ? config.lighting->overcast : 1.0;  // flat light: a grey sky
  env.air_k = air_c + kCelsius;
  if (light.enabled) {
    env.sun_w_m2 = kSunW * light.direct;
    env.sky_w_m2 = kSkyW * light.ambient * std::clamp(2.0 * light.to_sun.z, 0.0, 1.0);
  } else {
    env.sky_w_m2 = kSkyW * 0.55;  // flat light: an overcast noon
  }
  env.cooling_w_m2 = kClearSkyLossW * (1.0 - 0.9 * overcast);
  env.sky_k = env.air_k - 40.0 * (1.0 - 0.8 * overcast);
  return env;
}

double SurfaceK(Heat heat, const cv::Scalar& bgr, double sunlit, const ThermalEnv& env,
                double clothing_pass) {
  const double h = HeatLossW(heat);
  const double e = env.sun_w_m2 * sunlit + env.sky_w_m2;
  return env.air_k + Absorptance(bgr) * e / h + BodyPass(heat, clothing_pass) * (kSkinK - env.air_k) -
         env.cooling_w_m2 / h;
}

namespace {

// The ground in kelvin: solid where bare, a leaf's temperature where vegetated, under the air in
// water. The texture's colours carry the baked shadows: undone here (the shadow map says how
// much) before the colour gives the absorptance.
cv::Mat GroundKelvin(const RenderScene& rgb, const ThermalEnv& env) {
  const double dark = 1.0 - rgb.light.shadow_factor;
  cv::Mat out(rgb.texture.size(), CV_32F);
  for (int r = 0; r < rgb.texture.rows; ++r) {
    const auto* px = rgb.texture.ptr<cv::Vec3b>(r);
    const auto* veg = rgb.vegetation.ptr<std::uint8_t>(r);
    const auto* wet = rgb.wet.ptr<std::uint8_t>(r);
    const auto* shade = rgb.shadow.ptr<std::uint8_t>(r);
    auto* t = out.ptr<float>(r);
    for (int c = 0; c < rgb.texture.cols; ++c) {
      const double m = shade[c] / 255.0;
      const double unshade = 1.0 / std::max(0.05, 1.0 - dark * m);
      const cv::Scalar bgr(px[c][0] * unshade, px[c][1] * unshade, px[c][2] * unshade);
      const double sunlit = 1.0 - m;
      const double v = veg[c] / 255.0, w = wet[c] / 255.0;
      double k = (1 - v) * SurfaceK(Heat::kSolid, bgr, sunlit, env, 0) +
                 v * SurfaceK(Heat::kVegetation, bgr, sunlit, env, 0);
      k = (1 - w) * k + w * (env.air_k - kWaterBelowAirK);
      t[c] = static_cast<float>(k);
    }
  }
  return out;
}

std::vector<Drawable> DrawablesInKelvin(const std::vector<Drawable>& in, const ThermalEnv& env) {
  std::vector<Drawable> out = in;
  for (Drawable& d : out) d.parts = InKelvin(d.parts, env, 0);
  return out;
}

}  // namespace

RenderScene ThermalSceneOf(const RenderScene& rgb, const WorldConfig& config) {
  RenderScene s;
  s.texel_m = rgb.texel_m;
  s.origin_x_m = rgb.origin_x_m;
  s.top_y_m = rgb.top_y_m;
  s.light = rgb.light;
  const ThermalEnv env = ThermalEnvOf(config, rgb.light);
  s.sky = cv::Scalar(env.sky_k);
  s.box_below = cv::Scalar(env.air_k);
  s.underground = cv::Scalar(env.air_k);
  s.texture = GroundKelvin(rgb, env);
  for (const Figure& f : rgb.figures) {
    Figure g = f;
    g.parts = InKelvin(f.parts, env, f.clothing_pass);
    g.cover = InKelvin(f.cover, env, 0);
    s.figures.push_back(std::move(g));
  }
  s.flats = DrawablesInKelvin(rgb.flats, env);
  s.obstacles = DrawablesInKelvin(rgb.obstacles, env);
  return s;
}

}  // namespace swarmbox::physics::detail
