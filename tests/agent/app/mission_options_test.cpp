// The agent's --mission flags (mission_options.hpp): kinds, combinations, the world view.
#include "mission_options.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace swarmbox::agent {
namespace {

void ExpectError(const Status& s, const std::string& what) {
  ASSERT_FALSE(s.ok()) << "expected an error mentioning: " << what;
  EXPECT_EQ(s.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(s.error().ToString().find(what), std::string::npos) << s.error().ToString();
}

TEST(MissionOptions, ParsesBothKindsAndRejectsOthers) {
  EXPECT_EQ(*ParseMissionKind("plan"), MissionKind::kPlan);
  EXPECT_EQ(*ParseMissionKind("sar"), MissionKind::kSar);
  auto bad = ParseMissionKind("search");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().ToString().find("expected plan or sar"), std::string::npos) << bad.error().ToString();
}

TEST(MissionOptions, PlanIsTheDefaultAndNeedsNothingElse) {
  MissionOptions m;
  EXPECT_EQ(m.kind, MissionKind::kPlan);
  EXPECT_EQ(m.inference_latency_ms, 40);
  EXPECT_TRUE(ValidateMissionOptions(m, /*has_members=*/false, /*plan_given=*/true).ok());
}

TEST(MissionOptions, PlanTakesNoWorldNorPayload) {
  MissionOptions m;
  m.world_path = "w.yaml";
  ExpectError(ValidateMissionOptions(m, true, false), "--world is for --mission sar");
  m.world_path.clear();
  m.payload = "stretcher";
  ExpectError(ValidateMissionOptions(m, true, false), "--payload is for --mission sar");
  m.payload.clear();
  m.tuning_json = R"({"scout_altitude_m": 12})";
  ExpectError(ValidateMissionOptions(m, true, false), "--mission-tuning is for --mission sar");
}

TEST(MissionOptions, SarNeedsMembersAndAWorldAndNoPlan) {
  MissionOptions m;
  m.kind = MissionKind::kSar;
  m.world_path = "w.yaml";
  EXPECT_TRUE(ValidateMissionOptions(m, true, false).ok());
  ExpectError(ValidateMissionOptions(m, false, false), "needs --members");
  ExpectError(ValidateMissionOptions(m, true, true), "--plan is for --mission plan");
  m.world_path.clear();
  ExpectError(ValidateMissionOptions(m, true, false), "needs --world");
}

TEST(MissionOptions, LatencyMustBeInRange) {
  MissionOptions m;
  m.inference_latency_ms = -1;
  ExpectError(ValidateMissionOptions(m, false, false), "--inference-latency-ms -1");
  m.inference_latency_ms = kMaxInferenceLatencyMs + 1;
  ExpectError(ValidateMissionOptions(m, false, false), "--inference-latency-ms");
  m.inference_latency_ms = 0;
  EXPECT_TRUE(ValidateMissionOptions(m, false, false).ok());
}

TEST(WorldView, ReadsTheShippedOpenFieldGeofenceAndHome) {
  auto w = LoadWorldView(SWARMBOX_TRIALS_DIR "/worlds/open_field.yaml");
  ASSERT_TRUE(w.ok()) << w.error().ToString();
  EXPECT_EQ(w->name, "open_field");
  EXPECT_DOUBLE_EQ(w->size_x_m, 200.0);
  EXPECT_DOUBLE_EQ(w->size_y_m, 200.0);
  EXPECT_TRUE(w->has_home);
  EXPECT_NEAR(w->home_lat_deg, 47.397742, 1e-9);
}

class WorldFile : public ::testing::Test {
 protected:
  std::string Write(const std::string& text) {
    path_ = (std::filesystem::temp_directory_path() / ("swarmbox_world_view_" + std::to_string(::getpid()) + ".yaml")).string();
    std::ofstream(path_) << text;
    return path_;
  }
  void TearDown() override {
    if (!path_.empty()) std::filesystem::remove(path_);
  }
  std::string path_;
};

TEST_F(WorldFile, DefaultsWhenTheGeofenceIsAbsent) {
  auto w = LoadWorldView(Write("name: tiny\nvictims: []\n"));
  ASSERT_TRUE(w.ok()) << w.error().ToString();
  EXPECT_DOUBLE_EQ(w->size_x_m, 200.0);
  EXPECT_FALSE(w->has_home);
}

TEST_F(WorldFile, RejectsANonPositiveGeofenceWithItsPlace) {
  auto w = LoadWorldView(Write("name: bad\ngeofence: {size_x_m: -5, size_y_m: 10}\n"));
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().ToString().find("size_x_m must be > 0"), std::string::npos) << w.error().ToString();
  EXPECT_NE(w.error().ToString().find(":2:"), std::string::npos) << w.error().ToString();
}

TEST(WorldView, MissingFileIsNotFound) {
  auto w = LoadWorldView("/nonexistent/world.yaml");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.error().code(), ErrorCode::kNotFound);
}

TEST(ElectionTimeout, TheSarLifterWaitsTwiceAsLongEveryoneElseAsConfigured) {
  MissionOptions scout;
  scout.kind = MissionKind::kSar;
  EXPECT_EQ(ElectionTimeoutMsFor(scout, 1500), 1500);
  MissionOptions lifter = scout;
  lifter.payload = "stretcher";
  EXPECT_EQ(ElectionTimeoutMsFor(lifter, 1500), 3000);
  // Raft's timeouts are drawn from [T, 2T): the lifter's earliest is every scout's latest.
  EXPECT_GE(ElectionTimeoutMsFor(lifter, 500), 2 * ElectionTimeoutMsFor(scout, 500));
  MissionOptions plan;  // the built-in plan has no rescue to protect
  EXPECT_EQ(ElectionTimeoutMsFor(plan, 500), 500);
}

}  // namespace
}  // namespace swarmbox::agent
