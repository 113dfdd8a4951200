#include "swarmbox/physics/airframe.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace swarmbox::physics {
namespace {

using testing::AirframePath;

Result<Airframe> ParseText(const std::string& text) {
  auto doc = yaml::Parse(text, "af.yaml");
  if (!doc) return doc.error();
  return ParseAirframe(*doc, "af.yaml");
}

constexpr const char* kMinimal = R"(name: mini
mass_kg: 1.0
inertia_kg_m2: [0.01, 0.01, 0.02]
base_height_m: 0.1
collision: {box_m: [0.3, 0.3, 0.1]}
motor: {motor_constant: 1.0e-5, moment_constant: 0.01, time_constant_up_s: 0.01,
        time_constant_down_s: 0.02, max_rot_velocity_rad_s: 1000}
rotors:
  - {position_m: [0.1, -0.1, 0], direction: ccw}
  - {position_m: [-0.1, 0.1, 0], direction: ccw}
  - {position_m: [0.1, 0.1, 0], direction: cw}
  - {position_m: [-0.1, -0.1, 0], direction: cw}
)";

TEST(Airframe, X500MatchesPx4GazeboModel) {
  auto af = LoadAirframe(AirframePath("x500"));
  ASSERT_TRUE(af.ok()) << af.error().ToString();
  // PX4-gazebo-models models/x500/model.sdf and models/x500_base/model.sdf
  EXPECT_EQ(af->name, "x500");
  EXPECT_DOUBLE_EQ(af->motor.motor_constant, 8.54858e-06);
  EXPECT_DOUBLE_EQ(af->motor.moment_constant, 0.016);
  EXPECT_DOUBLE_EQ(af->motor.time_constant_up_s, 0.0125);
  EXPECT_DOUBLE_EQ(af->motor.time_constant_down_s, 0.025);
  EXPECT_DOUBLE_EQ(af->motor.max_rot_velocity_rad_s, 1000.0);
  EXPECT_DOUBLE_EQ(af->motor.rotor_drag_coefficient, 8.06428e-05);
  EXPECT_DOUBLE_EQ(af->motor.rolling_moment_coefficient, 1e-06);
  EXPECT_NEAR(af->mass_kg, 2.0 + 4 * 0.016076923, 1e-3);
  EXPECT_DOUBLE_EQ(af->inertia_kg_m2.z, 0.04000000000000001);
  ASSERT_EQ(af->rotors.size(), 4u);
  EXPECT_DOUBLE_EQ(af->rotors[0].position_m.x, 0.174);
  EXPECT_DOUBLE_EQ(af->rotors[0].position_m.y, -0.174);
  EXPECT_TRUE(af->rotors[0].ccw);
  EXPECT_FALSE(af->rotors[2].ccw);
  // Hover: m g = 4 k w^2 -> w ~ 770 rad/s (u ~ 0.77).
  EXPECT_NEAR(af->HoverRotorSpeed(), 769.6, 0.5);
}

TEST(Airframe, X8HeavyIsACoaxialOctoWithStretcher) {
  auto af = LoadAirframe(AirframePath("x8_heavy"));
  ASSERT_TRUE(af.ok()) << af.error().ToString();
  EXPECT_EQ(af->rotors.size(), 8u);
  EXPECT_NEAR(af->mass_kg, 120.0, 1e-9);
  ASSERT_EQ(af->payloads.size(), 1u);
  EXPECT_EQ(af->payloads[0].name, "stretcher");
  EXPECT_NEAR(af->payloads[0].mass_kg, 15.0, 1e-9);  // the empty stretcher (80 kg loaded at run time)
  int ccw = 0;
  for (const auto& r : af->rotors) ccw += r.ccw ? 1 : 0;
  EXPECT_EQ(ccw, 4);  // yaw-balanced
  // Over 200 kg take-off mass: max thrust at least 2x (120 + 80) kg.
  const double max_thrust = 8 * af->motor.motor_constant * af->motor.max_rot_velocity_rad_s * af->motor.max_rot_velocity_rad_s;
  EXPECT_GT(max_thrust / 9.80665, 200.0);
  EXPECT_GE(af->motor.time_constant_up_s, 0.1);
}

TEST(Airframe, ControlMappingPassesThroughUntouched) {
  auto af = ParseText(std::string(kMinimal) + "control:\n  rate: {p: 0.15, i: 0.2}\n  anything_goes: [1, 2]\n");
  ASSERT_TRUE(af.ok()) << af.error().ToString();
  ASSERT_TRUE(af->control.is_mapping());
  ASSERT_NE(af->control.Find("anything_goes"), nullptr);
  EXPECT_EQ(af->control.Find("rate")->Find("p")->scalar(), "0.15");
}

TEST(Airframe, UnknownKeyIsReportedWithFileLineColumn) {
  auto af = ParseText(std::string(kMinimal) + "wings: 2\n");
  ASSERT_FALSE(af.ok());
  EXPECT_EQ(af.error().where(), "af.yaml:13:1");
  EXPECT_NE(af.error().message().find("unknown key 'wings'"), std::string::npos) << af.error().message();
}

TEST(Airframe, NonPositiveMassIsRejectedAtItsValue) {
  std::string text = kMinimal;
  text.replace(text.find("mass_kg: 1.0"), 12, "mass_kg: -2.");
  auto af = ParseText(text);
  ASSERT_FALSE(af.ok());
  EXPECT_EQ(af.error().where(), "af.yaml:2:10");
  EXPECT_NE(af.error().message().find("'mass_kg' must be > 0"), std::string::npos) << af.error().message();
}

TEST(Airframe, BadRotorDirectionIsRejected) {
  std::string text = kMinimal;
  text.replace(text.find("direction: cw}"), 14, "direction: up}");
  auto af = ParseText(text);
  ASSERT_FALSE(af.ok());
  EXPECT_NE(af.error().message().find("rotor direction must be 'ccw' or 'cw' (got 'up')"), std::string::npos)
      << af.error().message();
  EXPECT_EQ(af.error().where(), "af.yaml:11:44");
}

TEST(Airframe, GpsFixDefaultsToStandalone) {
  auto af = ParseText(kMinimal);
  ASSERT_TRUE(af.ok()) << af.error().ToString();
  EXPECT_EQ(af->gps.fix, GpsFix::kStandalone);
  auto x500 = LoadAirframe(AirframePath("x500"));
  ASSERT_TRUE(x500.ok()) << x500.error().ToString();
  EXPECT_EQ(x500->gps.fix, GpsFix::kStandalone);
  EXPECT_EQ(x500->gps.horizontal_std_m, 0.8);
}

TEST(Airframe, RtkGpsTakesItsAccuracyFromTheReceiverModel) {
  auto af =
      ParseText(std::string(kMinimal) + "sensors:\n  gps: {rate_hz: 20, fix: rtk, rtk_baseline_km: 5}\n");
  ASSERT_TRUE(af.ok()) << af.error().ToString();
  EXPECT_EQ(af->gps.fix, GpsFix::kRtk);
  EXPECT_EQ(af->gps.rtk_baseline_km, 5.0);
  EXPECT_EQ(af->gps.rate_hz, 20.0);
  EXPECT_NEAR(af->gps.horizontal_std_m, 0.015 / 1.1774, 1e-9);  // 0.01 m + 5 ppm of 5 km, CEP
  EXPECT_NEAR(af->gps.vertical_std_m, 0.015 / 0.6745, 1e-9);    // R50
  auto dflt = ParseText(std::string(kMinimal) + "sensors:\n  gps: {fix: rtk}\n");
  ASSERT_TRUE(dflt.ok()) << dflt.error().ToString();
  EXPECT_EQ(dflt->gps.rtk_baseline_km, 1.0);
  EXPECT_NEAR(dflt->gps.horizontal_std_m, 0.011 / 1.1774, 1e-9);
}

TEST(Airframe, BadGpsFixSettingsAreRejectedClearly) {
  struct Case {
    const char* gps;
    const char* message;
  };
  for (const Case& c : {
           Case{"{fix: dgps}", "gps fix must be 'standalone' or 'rtk' (got 'dgps')"},
           Case{"{fix: rtk, horizontal_std_m: 0.5}", "gps horizontal_std_m is set by the RTK receiver model"},
           Case{"{fix: rtk, rate_hz: 25}", "gps rate_hz must be at most 20 with fix: rtk"},
           Case{"{fix: rtk, rtk_baseline_km: 500}", "gps rtk_baseline_km must be at most 100"},
           Case{"{fix: rtk, rtk_baseline_km: -1}", "'rtk_baseline_km' must be >= 0"},
           Case{"{rtk_baseline_km: 2}", "gps rtk_baseline_km needs fix: rtk"},
       }) {
    auto af = ParseText(std::string(kMinimal) + "sensors:\n  gps: " + c.gps + "\n");
    ASSERT_FALSE(af.ok()) << c.gps;
    EXPECT_NE(af.error().message().find(c.message), std::string::npos)
        << c.gps << ": " << af.error().message();
    EXPECT_EQ(af.error().where().rfind("af.yaml:14:", 0), 0u) << c.gps << ": " << af.error().where();
  }
}

TEST(Airframe, MissingFileIsNotFound) {
  auto af = LoadAirframe("/nonexistent/x.yaml");
  ASSERT_FALSE(af.ok());
  EXPECT_EQ(af.error().code(), ErrorCode::kNotFound);
  EXPECT_NE(af.error().message().find("cannot open file"), std::string::npos);
}

TEST(Airframe, SyntaxErrorIsReportedWithPosition) {
  auto af = ParseText("name: [unclosed\n");
  ASSERT_FALSE(af.ok());
  EXPECT_EQ(af.error().where().rfind("af.yaml:", 0), 0u) << af.error().where();
}

TEST(Airframe, AbsentStereoKeyIsOffAndTheScoutHasNone) {
  auto af = ParseText(kMinimal);
  ASSERT_TRUE(af.ok()) << af.error().ToString();
  EXPECT_FALSE(af->stereo.enabled);
  auto x500 = LoadAirframe(AirframePath("x500"));
  ASSERT_TRUE(x500.ok()) << x500.error().ToString();
  EXPECT_FALSE(x500->stereo.enabled);  // existing trials keep their behaviour: no depth
}

TEST(Airframe, StereoSectionIsReadAndItsErrorsKeepTheirPlace) {
  auto af = ParseText(std::string(kMinimal) + "stereo: {baseline_m: 0.1, width_px: 320, height_px: 200}\n");
  ASSERT_TRUE(af.ok()) << af.error().ToString();
  EXPECT_TRUE(af->stereo.enabled);
  EXPECT_DOUBLE_EQ(af->stereo.baseline_m, 0.1);
  EXPECT_EQ(af->stereo.width_px, 320);
  auto bad = ParseText(std::string(kMinimal) + "stereo: {baseline_m: 0.1, lens: fisheye}\n");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().ToString().find("lens"), std::string::npos) << bad.error().ToString();
  EXPECT_EQ(bad.error().where().rfind("af.yaml:", 0), 0u) << bad.error().where();
}

// x500_depth / x8_heavy_depth are their base file plus `stereo:` (trials/sensors/oak_d_pro_stereo.yaml's
// figures): the same document key for key otherwise, so a change to the base must be made to both.
TEST(Airframe, DepthVariantsAreTheirBasePlusStereo) {
  auto reference = yaml::ParseFile(testing::TrialsDir() + "/sensors/oak_d_pro_stereo.yaml");
  ASSERT_TRUE(reference.ok()) << reference.error().ToString();
  for (const char* base : {"x500", "x8_heavy"}) {
    auto base_doc = yaml::ParseFile(AirframePath(base));
    auto depth_doc = yaml::ParseFile(AirframePath(std::string(base) + "_depth"));
    ASSERT_TRUE(base_doc.ok() && depth_doc.ok()) << base;
    ASSERT_NE(depth_doc->Find("stereo"), nullptr) << base;
    yaml::Node stereo = *depth_doc->Find("stereo");
    depth_doc->Erase("stereo");
    EXPECT_TRUE(*depth_doc == *base_doc) << base << "_depth.yaml differs from " << base << ".yaml above `stereo:`";
    // The reference's figures, but where the camera sits on this airframe.
    yaml::Node figures = *reference->Find("stereo");
    figures.Set("offset_m", *stereo.Find("offset_m"));
    EXPECT_TRUE(stereo == figures) << base << "_depth.yaml's stereo: is not oak_d_pro_stereo.yaml's";
    auto af = LoadAirframe(AirframePath(std::string(base) + "_depth"));
    ASSERT_TRUE(af.ok()) << af.error().ToString();
    EXPECT_TRUE(af->stereo.enabled);
    EXPECT_EQ(af->name, base);
  }
}

}  // namespace
}  // namespace swarmbox::physics
