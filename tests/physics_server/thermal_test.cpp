// The thermal camera: the `thermal:` key (ParseThermalSpec), the surfaces' temperatures
// (detail::SurfaceK) and the renderer's people, noise and truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "detail/render_scene.hpp"
#include "detail/thermal_scene.hpp"
#include "swarmbox/airframe/airframe.hpp"
#include "swarmbox/airframe/thermal_spec.hpp"
#include "swarmbox/physics/thermal_renderer.hpp"
#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::physics {
namespace {

using airframe::ParseThermalSpec;
using airframe::ThermalSpec;

Result<ThermalSpec> ParseText(const std::string& text) {
  auto doc = yaml::Parse(text, "sensor.yaml");
  if (!doc) return doc.error();
  return ParseThermalSpec(doc->Find("thermal"));
}

ThermalSpec ShippedSpec() {
  auto doc = yaml::ParseFile(std::string(SWARMBOX_TRIALS_DIR) + "/sensors/boson_320_thermal.yaml");
  EXPECT_TRUE(doc.ok()) << doc.error().ToString();
  auto spec = ParseThermalSpec(doc->Find("thermal"));
  EXPECT_TRUE(spec.ok()) << spec.error().ToString();
  return spec.ok() ? *spec : ThermalSpec{};
}

// A rubble field at `time_h`, `overcast`, `air_c`, with one lying person in `clothing` at the
// origin (heading along +x) and a backpack of the same colour 4 m north of them.
WorldConfig World(double time_h, double overcast, double air_c, Bgr clothing = {90, 90, 95}) {
  WorldConfig w;
  w.name = "thermal";
  w.lighting = Lighting{time_h, overcast, air_c};
  w.terrain = Terrain{TerrainKind::kRubble, 0.0};
  w.victims.push_back({.id = "v", .x_m = 0.0, .y_m = 0.0, .heading_rad = 0.0, .clothing_bgr = clothing});
  w.distractors.push_back({.kind = DistractorKind::kBackpack,
                           .x_m = 0.0,
                           .y_m = 4.0,
                           .heading_rad = 0.0,
                           .size_m = 0.5,
                           .colour_bgr = clothing});
  return w;
}

cv::Mat Kelvin(const ThermalImage& img) {
  cv::Mat counts(img.height_px, img.width_px, CV_16U, const_cast<std::uint16_t*>(img.centikelvin.data()));
  cv::Mat k;
  counts.convertTo(k, CV_64F, 1.0 / kThermalCountsPerK);
  return k;
}

double Median(const cv::Mat& k) {
  std::vector<double> v(k.begin<double>(), k.end<double>());
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

TEST(ThermalSpec, AbsentKeyIsOff) {
  auto spec = ParseText("name: x\n");
  ASSERT_TRUE(spec.ok()) << spec.error().ToString();
  EXPECT_FALSE(spec->enabled);
}

TEST(ThermalSpec, ReferenceFileIsTheBoson320) {
  const ThermalSpec spec = ShippedSpec();
  EXPECT_TRUE(spec.enabled);
  EXPECT_EQ(spec.width_px, 320);  // "Array format 320x256" [B1]
  EXPECT_EQ(spec.height_px, 256);
  EXPECT_DOUBLE_EQ(spec.rate_hz, 8.6);
  EXPECT_DOUBLE_EQ(spec.netd_k, 0.05);
  // 12 um pixels behind a 4.3 mm lens: f = 4.3 / 0.012 = 358.3 px.
  EXPECT_NEAR(spec.FocalPx(), 4.3 / 0.012, 0.2);
}

// An airframe carries the camera under `thermal:` (airframe::ReadThermal): the x500 scouts do, the
// x8_heavy lifter does not.
TEST(ThermalSpec, TheScoutsAirframeCarriesItUnderThermal) {
  auto x500 = airframe::LoadAirframe(std::string(SWARMBOX_TRIALS_DIR) + "/airframes/x500.yaml");
  ASSERT_TRUE(x500.ok()) << x500.error().ToString();
  EXPECT_TRUE(x500->thermal.enabled);
  const ThermalSpec shipped = ShippedSpec();
  EXPECT_EQ(x500->thermal.width_px, shipped.width_px);
  EXPECT_EQ(x500->thermal.height_px, shipped.height_px);
  EXPECT_DOUBLE_EQ(x500->thermal.hfov_rad, shipped.hfov_rad);
  EXPECT_DOUBLE_EQ(x500->thermal.netd_k, shipped.netd_k);
  auto lifter = airframe::LoadAirframe(std::string(SWARMBOX_TRIALS_DIR) + "/airframes/x8_heavy.yaml");
  ASSERT_TRUE(lifter.ok()) << lifter.error().ToString();
  EXPECT_FALSE(lifter->thermal.enabled);

  std::ifstream in(std::string(SWARMBOX_TRIALS_DIR) + "/airframes/x8_heavy.yaml");
  std::stringstream text;
  text << in.rdbuf();
  auto bad = yaml::Parse(text.str() + "thermal: {netd_k: 3}\n", "x8_thermal.yaml");
  ASSERT_TRUE(bad.ok());
  EXPECT_FALSE(airframe::ParseAirframe(*bad).ok());
  // A frame is taken with each camera frame: a core slower than the camera is refused.
  auto slow = yaml::Parse(text.str() + "thermal: {rate_hz: 2}\n", "x8_thermal.yaml");
  ASSERT_TRUE(slow.ok());
  auto refused = airframe::ParseAirframe(*slow);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().ToString().find("camera.rate_hz"), std::string::npos)
      << refused.error().ToString();
}

TEST(ThermalSpec, UnknownKeysAndANoisyCoreAreErrors) {
  auto unknown = ParseText("thermal: {width_px: 320, colour: red}\n");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().ToString().find("colour"), std::string::npos) << unknown.error().ToString();
  auto noisy = ParseText("thermal: {netd_k: 2.0}\n");
  ASSERT_FALSE(noisy.ok());
  EXPECT_NE(noisy.error().ToString().find("netd_k"), std::string::npos) << noisy.error().ToString();
  auto tiny = ParseText("thermal: {width_px: 8}\n");
  EXPECT_FALSE(tiny.ok());
}

// The energy balance's cases: a clear noon's sun warms a dark backpack as much as the clothing
// of the same colour (only the body's warmth through it differs), both far above the rubble; at
// night the backpack cools under the air and the clothing stays above it.
TEST(ThermalScene, InTheNoonSunADarkBackpackIsAsWarmAsClothingAtNightItIsNot) {
  const cv::Scalar dark_blue(120, 60, 30), rubble(125, 130, 135);
  const WorldConfig noon = World(12.0, 0.0, 20.0);
  const detail::ThermalEnv day = detail::ThermalEnvOf(noon, detail::LightOf(noon));
  const double pack = detail::SurfaceK(detail::Heat::kSheet, dark_blue, 1.0, day, 0);
  const double jacket =
      detail::SurfaceK(detail::Heat::kClothing, dark_blue, 1.0, day, detail::kClothingPass[2]);
  const double ground = detail::SurfaceK(detail::Heat::kSolid, rubble, 1.0, day, 0);
  EXPECT_GT(pack, day.air_k + 20.0);
  EXPECT_NEAR(jacket - pack, detail::kClothingPass[2] * (detail::kSkinK - day.air_k), 1e-9);
  EXPECT_LT(jacket - pack, 1.5);
  EXPECT_GT(pack, ground + 10.0);

  const WorldConfig midnight = World(0.0, 0.0, 10.0);
  const detail::ThermalEnv night = detail::ThermalEnvOf(midnight, detail::LightOf(midnight));
  const double cold_pack = detail::SurfaceK(detail::Heat::kSheet, dark_blue, 1.0, night, 0);
  const double fleece =
      detail::SurfaceK(detail::Heat::kClothing, dark_blue, 1.0, night, detail::kClothingPass[0]);
  EXPECT_LT(cold_pack, night.air_k);
  EXPECT_GT(fleece, night.air_k + 2.0);
  EXPECT_GT(fleece - cold_pack, 6.0);
  // Skin is the warmest thing there at night.
  EXPECT_NEAR(detail::SurfaceK(detail::Heat::kSkin, cv::Scalar(105, 140, 190), 1.0, night, 0),
              detail::kSkinK - night.cooling_w_m2 / 150.0, 1e-9);
}

// At dawn under cloud a person stands out of the rubble, the backpack beside them does not; the
// warm pixels lie in the person's truth box.
TEST(ThermalRenderer, AtDawnUnderCloudThePersonIsTheWarmThingInView) {
  const WorldConfig config = World(6.5, 1.0, 8.0);
  ThermalRenderer renderer(config);
  const ThermalSpec spec = ShippedSpec();
  ThermalImage img;
  std::vector<VisiblePerson> people;
  renderer.Render(Pose{Vec3{0, 2, 18}, Quat{}}, spec, 7, &img, &people);
  ASSERT_EQ(people.size(), 1u);
  EXPECT_NEAR(people[0].visible_fraction, 1.0, 1e-9);
  const cv::Mat k = Kelvin(img);
  const double background = Median(k);
  EXPECT_NEAR(background, renderer.air_k(), 3.0);
  const cv::Rect box = people[0].box_px;
  double person_max = 0;
  cv::minMaxLoc(k(box), nullptr, &person_max);
  EXPECT_GT(person_max, background + 5.0);
  // Every pixel 3 K over the background is the person's (the blur spreads it by a pixel or two).
  const cv::Rect grown(box.x - 2, box.y - 2, box.width + 4, box.height + 4);
  int warm = 0, outside = 0;
  for (int y = 0; y < k.rows; ++y) {
    for (int x = 0; x < k.cols; ++x) {
      if (k.at<double>(y, x) < background + 3.0) continue;
      ++warm;
      if (!grown.contains(cv::Point(x, y))) ++outside;
    }
  }
  EXPECT_GT(warm, 30);
  EXPECT_EQ(outside, 0);
}

TEST(ThermalRenderer, NoiseIsTheCoresNetdAndTheSameSeedGivesTheSameFrame) {
  const WorldConfig config = World(10.0, 0.5, 15.0);
  ThermalRenderer renderer(config);
  const ThermalSpec spec = ShippedSpec();
  const Pose pose{Vec3{3, -2, 30}, Quat{}};
  ThermalImage a, b, again;
  renderer.Render(pose, spec, 1, &a);
  renderer.Render(pose, spec, 2, &b);
  renderer.Render(pose, spec, 1, &again);
  EXPECT_EQ(a.centikelvin, again.centikelvin);
  ASSERT_NE(a.centikelvin, b.centikelvin);
  cv::Mat diff = Kelvin(a) - Kelvin(b);
  cv::Scalar mean, std;
  cv::meanStdDev(diff, mean, std);
  // Two frames' noise: sqrt(2) x NETD (plus 0.01 K steps); their offsets differ by a constant.
  EXPECT_NEAR(std[0] / std::sqrt(2.0), spec.netd_k, 0.1 * spec.netd_k);
  EXPECT_LT(std::abs(mean[0]), 5 * spec.offset_std_k);
}

}  // namespace
}  // namespace swarmbox::physics
