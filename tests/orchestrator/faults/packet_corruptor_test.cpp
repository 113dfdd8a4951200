#include "swarmbox/faults/packet_corruptor.hpp"

#include <gtest/gtest.h>

#include <array>
#include <vector>

namespace swarmbox::faults {
namespace {

TEST(PacketCorruptor, ChoosesTheConfiguredFractionOfPackets) {
  // netem "corrupt 10%": each packet independently. Over 100,000 packets the chosen fraction's sd is
  // sqrt(0.1 x 0.9 / 100000) = 0.095 %; allow 5 of them.
  PacketCorruptor corrupt(0.1, 42);
  int chosen = 0;
  for (int i = 0; i < 100000; ++i) chosen += corrupt.Choose(1000).has_value();
  EXPECT_NEAR(chosen / 100000.0, 0.1, 0.005);
}

TEST(PacketCorruptor, EveryBitOfThePacketCanBeChosenAndNoneOutside) {
  // Certain corruption of a 4-byte packet: every one of its 32 bits comes up, about 1/32 of the time
  // (20,000 draws: 625 expected per bit, sd 24.6; allow 6 of them).
  PacketCorruptor corrupt(1.0, 7);
  std::array<int, 32> hits{};
  for (int i = 0; i < 20000; ++i) {
    auto bit = corrupt.Choose(4);
    ASSERT_TRUE(bit.has_value());
    ASSERT_LT(*bit, 32u);
    ++hits[*bit];
  }
  for (std::size_t b = 0; b < hits.size(); ++b) EXPECT_NEAR(hits[b], 625, 150) << "bit " << b;
}

TEST(PacketCorruptor, NothingToFlipInAnEmptyPacketOrAtZeroPercent) {
  PacketCorruptor certain(1.0, 1);
  EXPECT_FALSE(certain.Choose(0).has_value());
  PacketCorruptor never(0.0, 1);
  for (int i = 0; i < 1000; ++i) ASSERT_FALSE(never.Choose(1500).has_value());
}

TEST(PacketCorruptor, SameSeedSameChoices) {
  PacketCorruptor a(0.3, 99), b(0.3, 99), c(0.3, 100);
  int differ = 0;
  for (int i = 0; i < 1000; ++i) {
    const auto ca = a.Choose(1500);
    ASSERT_EQ(ca, b.Choose(1500));
    differ += ca != c.Choose(1500);
  }
  EXPECT_GT(differ, 0);
}

TEST(FlipBit, FlipsExactlyTheNamedBit) {
  std::vector<std::uint8_t> bytes = {0x00, 0xff, 0x10};
  FlipBit(bytes, 8 + 7);  // byte 1, most significant bit
  EXPECT_EQ(bytes, (std::vector<std::uint8_t>{0x00, 0x7f, 0x10}));
  FlipBit(bytes, 2 * 8 + 4);  // byte 2, 0x10 -> 0x00
  FlipBit(bytes, 0);          // byte 0, least significant bit
  EXPECT_EQ(bytes, (std::vector<std::uint8_t>{0x01, 0x7f, 0x00}));
}

TEST(FlipBitDeathTest, ABitOutsideThePacketAborts) {
  std::vector<std::uint8_t> bytes(2);
  EXPECT_DEATH(FlipBit(bytes, 16), "");
}

}  // namespace
}  // namespace swarmbox::faults
