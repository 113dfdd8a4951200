#include "swarmbox/common/split.hpp"

#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

namespace swarmbox {
namespace {

using Pieces = std::vector<std::string_view>;

TEST(SplitOn, SplitsAtEverySeparator) {
  EXPECT_EQ(SplitOn("t,x,y,z", ','), (Pieces{"t", "x", "y", "z"}));
  EXPECT_EQ(SplitOn("world.drones.0.name", '.'), (Pieces{"world", "drones", "0", "name"}));
}

TEST(SplitOn, KeepsEmptyPieces) {
  EXPECT_EQ(SplitOn("a,,b", ','), (Pieces{"a", "", "b"}));
  EXPECT_EQ(SplitOn(",a,", ','), (Pieces{"", "a", ""}));
  EXPECT_EQ(SplitOn(",", ','), (Pieces{"", ""}));
}

TEST(SplitOn, TextWithoutSeparatorIsOnePiece) {
  EXPECT_EQ(SplitOn("abc", ','), (Pieces{"abc"}));
  EXPECT_EQ(SplitOn("", ','), (Pieces{""}));
}

TEST(SplitOn, PiecesPointIntoTheText) {
  const std::string row = "12.5,drone_1";
  const Pieces cells = SplitOn(row, ',');
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_EQ(cells[1].data(), row.data() + 5);
  EXPECT_EQ(cells[1].size(), 7u);
}

}  // namespace
}  // namespace swarmbox
