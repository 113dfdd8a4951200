// ParseBrainArgs: --brain-args JSON into Context::args; errors with line:col.
#include "swarmbox/brain/args.hpp"

#include <gtest/gtest.h>

namespace swarmbox::brain {
namespace {

using Args = std::map<std::string, std::string>;

TEST(BrainArgs, ScalarsBecomeTheirText) {
  auto args = ParseBrainArgs(R"({"altitude_m": 12, "radius_m": 6.5, "name": "ring", "quoted": "7",
                               "fast": true})");
  ASSERT_TRUE(args) << args.error().ToString();
  EXPECT_EQ(*args, (Args{{"altitude_m", "12"}, {"radius_m", "6.5"}, {"name", "ring"}, {"quoted", "7"},
                         {"fast", "true"}}));
}

TEST(BrainArgs, NestedValuesBecomeTheirJsonText) {
  auto args = ParseBrainArgs(R"({"ring": {"n": 3, "names": ["a", "b"]}, "list": [1, 2.5]})");
  ASSERT_TRUE(args) << args.error().ToString();
  EXPECT_EQ(*args, (Args{{"ring", R"({"n":3,"names":["a","b"]})"}, {"list", "[1,2.5]"}}));
}

TEST(BrainArgs, EmptyTextAndEmptyObjectAndNullValues) {
  auto empty = ParseBrainArgs("");
  auto object = ParseBrainArgs("{}");
  auto nulls = ParseBrainArgs(R"({"a": null, "b": 1})");
  ASSERT_TRUE(empty && object && nulls);
  EXPECT_TRUE(empty->empty());
  EXPECT_TRUE(object->empty());
  EXPECT_EQ(*nulls, (Args{{"b", "1"}}));  // null: as if absent, the brain's default applies
}

TEST(BrainArgs, NotAnObjectSaysWhere) {
  auto args = ParseBrainArgs("[1, 2]");
  ASSERT_FALSE(args);
  EXPECT_EQ(args.error().ToString(), "--brain-args:1:1: brain arguments must be a JSON object ({\"key\": value, ...})");
}

TEST(BrainArgs, SyntaxErrorHasLineAndColumn) {
  auto args = ParseBrainArgs("{\"a\": 1,\n \"b\": [1, 2}", "trial.yaml brain.args");
  ASSERT_FALSE(args);
  EXPECT_EQ(args.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(args.error().where().rfind("trial.yaml brain.args:2:", 0), 0u) << args.error().ToString();
}

TEST(BrainArgs, DuplicateKeyIsAnError) {
  auto args = ParseBrainArgs(R"({"a": 1, "a": 2})");
  ASSERT_FALSE(args);
  EXPECT_EQ(args.error().ToString(), "--brain-args:1:10: duplicate key 'a'");
}

}  // namespace
}  // namespace swarmbox::brain
