// The recording's keys (`record: {enabled, rate_hz, camera_hz, camera_scale, jpeg_quality}`):
// defaults (on, issue #20's figures), values, --set, and errors at file:line:col.
#include <gtest/gtest.h>

#include <string>

#include "swarmbox/dsl/trial_loader.hpp"

namespace swarmbox::dsl {
namespace {

constexpr const char* kTrial = R"(name: rec
world: worlds/open_field.yaml
drones:
  - {name: scout_1, airframe: x500}
timeout: {sim: 60s}
)";

LoadOptions Opts(std::vector<std::string> overrides = {}) {
  LoadOptions o;
  o.trials_dir = "/trials";
  o.file_exists = [](const std::string& p) {
    return p == "/trials/worlds/open_field.yaml" || p == "/trials/airframes/x500.yaml" ||
           p == "/trials/radios/wifi_5ghz_mesh.yaml";
  };
  o.overrides = std::move(overrides);
  return o;
}

TEST(RecordKeys, OnByDefaultWithTheContractsFigures) {
  auto spec = LoadTrialText(kTrial, "rec.yaml", Opts());
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_TRUE(spec->record.enabled);
  EXPECT_EQ(spec->record.rate_hz, 10.0);
  EXPECT_EQ(spec->record.camera_hz, 1.0);
  EXPECT_EQ(spec->record.camera_scale, 0.5);
  EXPECT_EQ(spec->record.jpeg_quality, 75);
}

TEST(RecordKeys, ValuesAndSetAreRead) {
  auto spec = LoadTrialText(std::string(kTrial) + "record: {rate_hz: 25, camera_hz: 0, camera_scale: 1, jpeg_quality: 90}\n",
                            "rec.yaml", Opts());
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->record.rate_hz, 25.0);
  EXPECT_EQ(spec->record.camera_hz, 0.0);
  EXPECT_EQ(spec->record.camera_scale, 1.0);
  EXPECT_EQ(spec->record.jpeg_quality, 90);
  auto off = LoadTrialText(kTrial, "rec.yaml", Opts({"record.enabled=false"}));
  ASSERT_TRUE(off) << off.error().ToString();
  EXPECT_FALSE(off->record.enabled);
}

TEST(RecordKeys, BadValuesPointAtTheirKey) {
  auto rate = LoadTrialText(std::string(kTrial) + "record: {rate_hz: 0}\n", "rec.yaml", Opts());
  ASSERT_FALSE(rate);
  EXPECT_NE(rate.error().ToString().find("rec.yaml:6:19"), std::string::npos) << rate.error().ToString();
  EXPECT_NE(rate.error().message().find("'rate_hz' must be in (0, 250]"), std::string::npos);
  auto scale = LoadTrialText(std::string(kTrial) + "record: {camera_scale: 2}\n", "rec.yaml", Opts());
  ASSERT_FALSE(scale);
  EXPECT_NE(scale.error().message().find("'camera_scale' must be in (0, 1]"), std::string::npos);
  auto quality = LoadTrialText(std::string(kTrial) + "record: {jpeg_quality: 101}\n", "rec.yaml", Opts());
  ASSERT_FALSE(quality);
  EXPECT_NE(quality.error().message().find("'jpeg_quality' must be in [1, 100]"), std::string::npos);
  auto unknown = LoadTrialText(std::string(kTrial) + "record: {fps: 3}\n", "rec.yaml", Opts());
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().ToString().find("fps"), std::string::npos) << unknown.error().ToString();
}

}  // namespace
}  // namespace swarmbox::dsl
