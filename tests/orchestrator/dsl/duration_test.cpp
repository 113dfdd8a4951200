#include "swarmbox/dsl/duration.hpp"

#include <gtest/gtest.h>

namespace swarmbox::dsl {
namespace {

TEST(Duration, ParsesTheUnitsOfTrialFiles) {
  const std::pair<const char*, std::int64_t> cases[] = {
      {"30s", 30000}, {"500ms", 500}, {"2m", 120000}, {"1h", 3600000}, {"1.5s", 1500}, {"0s", 0},
  };
  for (const auto& [text, ms] : cases) {
    auto d = ParseDuration(text);
    ASSERT_TRUE(d) << text << ": " << d.error().ToString();
    EXPECT_EQ(d->ms(), ms) << text;
  }
}

TEST(Duration, RejectsWhatIsNotADuration) {
  const std::pair<const char*, const char*> cases[] = {
      {"30", "missing unit"}, {"30 s", "unknown unit ' s'"}, {"s", "expected a duration"},
      {"-3s", "expected a duration"}, {"2d", "unknown unit 'd'"}, {"0.5ms", "finer than a millisecond"},
  };
  for (const auto& [text, message] : cases) {
    auto d = ParseDuration(text);
    ASSERT_FALSE(d) << text;
    EXPECT_NE(d.error().message().find(message), std::string::npos) << d.error().message();
  }
}

TEST(Duration, PrintsTheShortestExactSpelling) {
  EXPECT_EQ(Duration::Ms(120000).ToString(), "2m");
  EXPECT_EQ(Duration::Ms(90000).ToString(), "90s");
  EXPECT_EQ(Duration::Ms(500).ToString(), "500ms");
  EXPECT_EQ(Duration::Ms(0).ToString(), "0s");
}

TEST(Duration, DecodeReportsTheNodesPlace) {
  auto doc = yaml::Parse("sim: 10 parsecs\n", "t.yaml");
  ASSERT_TRUE(doc);
  Duration d;
  auto s = Decode(*doc->Find("sim"), &d);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().where(), "t.yaml:1:6");
  EXPECT_NE(s.error().message().find("expected a duration such as 30s"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::dsl
