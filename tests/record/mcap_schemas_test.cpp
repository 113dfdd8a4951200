// The recording's JSON Schemas and timestamps (foxglove_schemas.hpp).
#include <gtest/gtest.h>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/record/foxglove_schemas.hpp"

namespace swarmbox::record {
namespace {

TEST(FoxgloveSchemas, EverySchemaIsAJsonObjectTitledWithItsName) {
  ASSERT_EQ(SchemaNames().size(), 13u);
  for (std::string_view name : SchemaNames()) {
    const std::string_view text = SchemaText(name);
    ASSERT_FALSE(text.empty()) << name;
    auto doc = yaml::Parse(text, name);
    ASSERT_TRUE(doc) << doc.error().ToString();
    ASSERT_TRUE(doc->is_mapping()) << name;
    ASSERT_NE(doc->Find("title"), nullptr) << name;
    EXPECT_EQ(doc->Find("title")->scalar(), name);
    EXPECT_EQ(doc->Find("type")->scalar(), "object");
    const yaml::Node* props = doc->Find("properties");
    ASSERT_NE(props, nullptr) << name;
    if (name != kFrameTransforms && name != kSceneUpdate) {
      EXPECT_NE(props->Find("timestamp"), nullptr) << name << " messages carry a timestamp";
    }
  }
}

TEST(FoxgloveSchemas, FieldsTheContractNames) {
  auto props = [](std::string_view name) {
    auto doc = yaml::Parse(SchemaText(name));
    EXPECT_TRUE(doc);
    return *doc->Find("properties");
  };
  for (const char* f : {"drone", "position", "velocity", "orientation"}) EXPECT_NE(props(kDroneTruth).Find(f), nullptr) << f;
  for (const char* f : {"flight_mode", "position", "velocity", "yaw"}) EXPECT_NE(props(kSetpoint).Find(f), nullptr) << f;
  for (const char* f : {"separation", "alignment", "cohesion", "sum"}) EXPECT_NE(props(kFlocking).Find(f), nullptr) << f;
  for (const char* f : {"role", "term", "leader", "commit_index"}) EXPECT_NE(props(kRaftState).Find(f), nullptr) << f;
  for (const char* f : {"battery_fraction", "mission_stage", "armed", "landed"}) {
    EXPECT_NE(props(kAgentStatus).Find(f), nullptr) << f;
  }
  for (const char* f : {"level", "name", "message", "file", "line"}) EXPECT_NE(props(kLog).Find(f), nullptr) << f;
  for (const char* f : {"frame_id", "format", "data"}) EXPECT_NE(props(kCompressedImage).Find(f), nullptr) << f;
  EXPECT_NE(props(kLinks).Find("links"), nullptr);
  EXPECT_NE(props(kSectors).Find("sectors"), nullptr);
  for (const char* f : {"drone", "position", "confidence"}) EXPECT_NE(props(kDetection).Find(f), nullptr) << f;
  const yaml::Node scene = props(kSceneUpdate);
  const yaml::Node* entity = scene.Find("entities")->Find("items")->Find("properties");
  for (const char* f : {"id", "frame_id", "cubes", "arrows", "lines", "metadata"}) EXPECT_NE(entity->Find(f), nullptr) << f;
}

TEST(FoxgloveSchemas, UnknownNamesHaveNoText) { EXPECT_TRUE(SchemaText("foxglove.Nope").empty()); }

TEST(FoxgloveSchemas, MakeChannelCarriesTheText) {
  const ChannelSpec spec = MakeChannel("/tf", kFrameTransforms);
  EXPECT_EQ(spec.topic, "/tf");
  EXPECT_EQ(spec.schema_name, "foxglove.FrameTransforms");
  EXPECT_EQ(spec.schema, SchemaText(kFrameTransforms));
}

TEST(FoxgloveSchemas, MakeChannelWithAnUnknownSchemaAborts) {
  EXPECT_DEATH(MakeChannel("/x", "swarmbox.Nope"), "check failed");
}

TEST(Timestamps, SplitNanosecondsIntoSecAndNsec) {
  EXPECT_EQ(JsonTimestamp(0), R"({"sec":0,"nsec":0})");
  EXPECT_EQ(JsonTimestamp(1'500'000'000), R"({"sec":1,"nsec":500000000})");
  EXPECT_EQ(JsonTimestamp(3'600'000'000'007), R"({"sec":3600,"nsec":7})");
  EXPECT_EQ(yaml::EmitJson(TimestampNode(2'000'000'001)), R"({"sec":2,"nsec":1})");
}

TEST(Timestamps, SecondsToNanosecondsRounds) {
  EXPECT_EQ(SecondsToNs(0.004), 4'000'000u);
  EXPECT_EQ(SecondsToNs(12.5), 12'500'000'000u);
  EXPECT_EQ(SecondsToNs(-1.0), 0u);
  EXPECT_EQ(SecondsToNs(0.1 + 0.2), 300'000'000u);
}

}  // namespace
}  // namespace swarmbox::record
