#include "swarmbox/common/yaml.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <optional>

namespace swarmbox::yaml {
namespace {

TEST(Yaml, ParsesNestedDocumentWithMarks) {
  auto doc = Parse("name: sar\ndrones:\n  - {name: scout_1, pose: [0, 1.5, 0]}\n", "t.yaml");
  ASSERT_TRUE(doc) << doc.error().ToString();
  const Node* drones = doc->Find("drones");
  ASSERT_NE(drones, nullptr);
  ASSERT_TRUE(drones->is_sequence());
  ASSERT_EQ(drones->items().size(), 1u);
  const Node& d = drones->items()[0];
  EXPECT_EQ(d.Find("name")->scalar(), "scout_1");
  EXPECT_EQ(d.mark().line, 3);
  EXPECT_EQ(d.mark().column, 5);
  EXPECT_DOUBLE_EQ(*d.Find("pose")->items()[1].AsDouble(), 1.5);
}

TEST(Yaml, SyntaxErrorReportsFileLineColumn) {
  auto doc = Parse("a: 1\nb: [1, 2\nc: 3\n", "bad.yaml");
  ASSERT_FALSE(doc);
  EXPECT_EQ(doc.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(doc.error().where().rfind("bad.yaml:", 0), 0u) << doc.error().where();
  EXPECT_NE(doc.error().ToString().find("bad.yaml:"), std::string::npos);
}

TEST(Yaml, DuplicateKeyIsAnError) {
  auto doc = Parse("a: 1\na: 2\n", "dup.yaml");
  ASSERT_FALSE(doc);
  EXPECT_EQ(doc.error().where(), "dup.yaml:2:1");
  EXPECT_NE(doc.error().message().find("duplicate key 'a'"), std::string::npos);
}

TEST(Yaml, QuotedNumbersStayStrings) {
  auto doc = Parse("a: \"1\"\nb: 1\nc: ~\nd: true\n");
  ASSERT_TRUE(doc);
  EXPECT_FALSE(doc->Find("a")->AsDouble());
  EXPECT_EQ(*doc->Find("a")->AsString(), "1");
  EXPECT_EQ(*doc->Find("b")->AsInt(), 1);
  EXPECT_TRUE(doc->Find("c")->is_null());
  EXPECT_TRUE(*doc->Find("d")->AsBool());
}

TEST(Yaml, ReadsJsonFromDocker) {
  auto doc = Parse(R"({"Id":"abc","Warnings":[],"State":{"Running":true,"ExitCode":0},"Msg":"a\"b\n"})",
                   "docker");
  ASSERT_TRUE(doc) << doc.error().ToString();
  EXPECT_EQ(doc->Find("Id")->scalar(), "abc");
  EXPECT_TRUE(doc->Find("Warnings")->is_sequence());
  EXPECT_TRUE(*doc->Find("State")->Find("Running")->AsBool());
  EXPECT_EQ(doc->Find("Msg")->scalar(), "a\"b\n");
}

TEST(Yaml, EmitJsonRoundTrips) {
  auto doc = Parse("s: \"7\"\nn: 7\nf: -0.5\nb: false\nz: null\nl: [a, 2]\nm: {k: 'v w'}\n");
  ASSERT_TRUE(doc);
  const std::string json = EmitJson(*doc);
  EXPECT_EQ(json, R"({"s":"7","n":7,"f":-0.5,"b":false,"z":null,"l":["a",2],"m":{"k":"v w"}})");
  auto back = Parse(json);
  ASSERT_TRUE(back);
  EXPECT_EQ(EmitJson(*back), json);
}

TEST(Yaml, JsonQuoteEscapesControlCharacters) {
  EXPECT_EQ(JsonQuote("a\tb\x01\"\\"), "\"a\\tb\\u0001\\\"\\\\\"");
}

TEST(Yaml, EmitReadsBackEqual) {
  auto doc = Parse(
      "name: sar\nempty: []\nquoted: \"yes: no\"\nnum: 3.5\nlist:\n  - a\n  - {x: 1, y: [1, 2]}\n"
      "map:\n  k: \"\"\n  dash: \"-x\"\n");
  ASSERT_TRUE(doc) << doc.error().ToString();
  const std::string text = Emit(*doc);
  auto back = Parse(text);
  ASSERT_TRUE(back) << back.error().ToString() << "\n" << text;
  EXPECT_TRUE(*back == *doc) << text;
}

TEST(Yaml, SetReplacesAndAppends) {
  Node m = Node::Mapping();
  m.Set("a", Node::Scalar("1"));
  m.Set("b", Node::Scalar("2"));
  m.Set("a", Node::Scalar("3"));
  ASSERT_EQ(m.entries().size(), 2u);
  EXPECT_EQ(m.Find("a")->scalar(), "3");
  EXPECT_TRUE(m.Erase("a"));
  EXPECT_EQ(m.Find("a"), nullptr);
}

TEST(MapReader, ReadsTypedFieldsAndDefaults) {
  auto doc = Parse("mass_kg: 2.0\nrotors: 4\nname: x500\npose: [1, 2, 3]\n", "af.yaml");
  ASSERT_TRUE(doc);
  double mass = 0;
  int rotors = 0;
  std::string name;
  std::array<double, 3> pose{};
  std::optional<double> drag;
  bool armed = true;
  MapReader r(*doc, "airframe");
  r.Required("mass_kg", &mass).Required("rotors", &rotors).Required("name", &name).Required("pose", &pose);
  r.Optional("drag", &drag).Optional("armed", &armed);
  ASSERT_TRUE(r.Finish());
  EXPECT_DOUBLE_EQ(mass, 2.0);
  EXPECT_EQ(rotors, 4);
  EXPECT_EQ(name, "x500");
  EXPECT_EQ(pose[2], 3.0);
  EXPECT_FALSE(drag.has_value());
  EXPECT_TRUE(armed);
}

TEST(MapReader, UnknownKeyNamesItAndTheAcceptedOnes) {
  auto doc = Parse("mass_kg: 2.0\nmas: 3\n", "af.yaml");
  ASSERT_TRUE(doc);
  double mass = 0;
  MapReader r(*doc, "airframe");
  r.Required("mass_kg", &mass);
  auto s = r.Finish();
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().ToString(), "af.yaml:2:1: unknown key 'mas' in airframe (accepted: mass_kg)");
}

// A key in the units' old spelling (issue #21) is an error naming the key as it is spelled now.
// The old key is written as "speed" "_mps" so that the rename script leaves this test as it is.
TEST(MapReader, OldUnitSpellingNamesTheNewKey) {
  auto doc = Parse("direction_deg: 270\nspeed" "_mps: 12\n", "trial.yaml");
  ASSERT_TRUE(doc);
  double speed = 0, direction = 0;
  MapReader r(*doc, "wind_gust");
  r.Optional("speed_m_s", &speed).Optional("direction_deg", &direction);
  auto s = r.Finish();
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().ToString(),
            "trial.yaml:2:1: unknown key 'speed" "_mps' in wind_gust: it is spelled 'speed_m_s' now "
            "(units are spelled _m_s, _m_s2, _rad_s, _deg_s)");
}

// A required key written in the old spelling gets the same answer, not "missing required key".
TEST(MapReader, OldUnitSpellingOfARequiredKeyNamesTheNewKey) {
  auto doc = Parse("direction_deg: 270\nspeed" "_mps: 12\n", "trial.yaml");
  ASSERT_TRUE(doc);
  double speed = 0, direction = 0;
  MapReader r(*doc, "wind_gust");
  r.Required("speed_m_s", &speed).Optional("direction_deg", &direction);
  auto s = r.Finish();
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().ToString(),
            "trial.yaml:2:1: unknown key 'speed" "_mps' in wind_gust: it is spelled 'speed_m_s' now "
            "(units are spelled _m_s, _m_s2, _rad_s, _deg_s)");
}

// An old suffix on a key that has no new spelling here is an ordinary unknown key.
TEST(MapReader, OldUnitSuffixOfNoKnownKeyIsAnUnknownKey) {
  auto doc = Parse("rate" "_radps: 1\n", "af.yaml");
  ASSERT_TRUE(doc);
  double mass = 0;
  MapReader r(*doc, "airframe");
  r.Optional("mass_kg", &mass);
  auto s = r.Finish();
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().ToString(), "af.yaml:1:1: unknown key 'rate" "_radps' in airframe (accepted: mass_kg)");
}

TEST(MapReader, MissingAndMistypedKeysSayWhere) {
  auto doc = Parse("rotors: four\n", "af.yaml");
  ASSERT_TRUE(doc);
  int rotors = 0;
  double mass = 0;
  {
    MapReader r(*doc, "airframe");
    r.Required("rotors", &rotors);
    auto s = r.Finish();
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().ToString(), "af.yaml:1:9: 'rotors': expected an integer, got 'four'");
  }
  {
    MapReader r(*doc, "airframe");
    r.Required("mass_kg", &mass).Optional("rotors", &rotors);
    auto s = r.Finish();
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().ToString(), "af.yaml:1:1: missing required key 'mass_kg' in airframe");
  }
}

TEST(MapReader, IntegerRangeIsChecked) {
  auto doc = Parse("n: -1\n", "r.yaml");
  ASSERT_TRUE(doc);
  std::uint32_t n = 0;
  MapReader r(*doc);
  r.Required("n", &n);
  auto s = r.Finish();
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message().find("out of range"), std::string::npos);
}

TEST(Yaml, MissingFileIsNotFound) {
  auto doc = ParseFile("/nonexistent/swarmbox.yaml");
  ASSERT_FALSE(doc);
  EXPECT_EQ(doc.error().code(), ErrorCode::kNotFound);
  EXPECT_EQ(doc.error().where(), "/nonexistent/swarmbox.yaml");
}

}  // namespace
}  // namespace swarmbox::yaml
