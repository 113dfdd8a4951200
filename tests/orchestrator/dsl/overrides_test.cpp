#include "swarmbox/dsl/overrides.hpp"

#include <gtest/gtest.h>

namespace swarmbox::dsl {
namespace {

yaml::Node Doc(const char* text) {
  auto d = yaml::Parse(text, "t.yaml");
  SWARMBOX_CHECK(d.ok());
  return *d;
}

TEST(ApplyOverride, SetsNestedKeysAndCreatesMissingMappings) {
  yaml::Node doc = Doc("seed: 1\n");
  ASSERT_TRUE(ApplyOverride(doc, "network.mesh.loss=0.1"));
  ASSERT_TRUE(ApplyOverride(doc, "seed=7"));
  EXPECT_EQ(doc.Find("seed")->scalar(), "7");
  EXPECT_EQ(doc.Find("network")->Find("mesh")->Find("loss")->scalar(), "0.1");
}

TEST(ApplyOverride, IndexesListsByPositionOrByName) {
  yaml::Node doc = Doc("drones:\n  - {name: a, pose: [0, 0, 0]}\n  - {name: b}\n");
  ASSERT_TRUE(ApplyOverride(doc, "drones.1.payload=stretcher"));
  ASSERT_TRUE(ApplyOverride(doc, "drones.a.pose=[1, 2, 3]"));
  EXPECT_EQ(doc.Find("drones")->items()[1].Find("payload")->scalar(), "stretcher");
  const yaml::Node* pose = doc.Find("drones")->items()[0].Find("pose");
  ASSERT_TRUE(pose->is_sequence());
  EXPECT_EQ(pose->items()[2].scalar(), "3");
}

TEST(ApplyOverride, ValueIsYaml) {
  yaml::Node doc = Doc("{}");
  ASSERT_TRUE(ApplyOverride(doc, "name=\"007\""));
  EXPECT_TRUE(doc.Find("name")->quoted());
  ASSERT_TRUE(ApplyOverride(doc, "payload="));
  EXPECT_TRUE(doc.Find("payload")->is_null());
}

TEST(ApplyOverride, ErrorsSayWhatIsWrong) {
  const std::pair<const char*, const char*> cases[] = {
      {"seed", "expected key=value"},
      {"=3", "expected key=value"},
      {"drones.5.name=x", "'drones.5': index 5 is past the end of a list of 1"},
      {"drones.zed.name=x", "'drones.zed': no list item named 'zed'"},
      {"seed.value=3", "'seed.value': cannot descend into a scalar (t.yaml:1:7)"},
      {"a..b=1", "empty path segment in key"},
  };
  for (const auto& [assignment, message] : cases) {
    yaml::Node doc = Doc("seed: 1\ndrones: [{name: a}]\n");
    auto s = ApplyOverride(doc, assignment);
    ASSERT_FALSE(s) << assignment;
    EXPECT_NE(s.error().message().find(message), std::string::npos)
        << assignment << " -> " << s.error().ToString();
  }
}

}  // namespace
}  // namespace swarmbox::dsl
