// The radio codec: round trips, versioning, and robustness against arbitrary bytes.
#include "swarmbox/raft/message_codec.hpp"

#include <gtest/gtest.h>

#include <random>

namespace swarmbox::raft {
namespace {

constexpr std::uint32_t kTag = 0xC0FFEEu;

Message Sample() {
  Message m;
  m.type = MessageType::kApp;
  m.from = 2;
  m.to = 5;
  m.term = 7;
  m.log_term = 6;
  m.index = 41;
  m.commit = 40;
  m.entries = {Entry{6, 42, EntryType::kNormal, Bytes{1, 2, 3}},
               Entry{7, 43, EntryType::kEmpty, {}}};
  return m;
}

TEST(MessageCodec, RoundTripsEveryWireType) {
  for (std::uint8_t t = 3; t <= kMaxMessageType; ++t) {
    Message m;
    m.type = static_cast<MessageType>(t);
    m.from = 1;
    m.to = 3;
    m.term = m.type == MessageType::kProp ? 0 : 300;
    m.reject = t % 2 == 0;
    m.reject_hint = 1u << 20;
    if (m.type == MessageType::kSnap) m.snapshot = Snapshot{99, 3, Bytes(1000, 7)};
    if (m.type == MessageType::kProp) m.entries = {Entry{0, 0, EntryType::kNormal, Bytes{9}}};
    auto back = DecodeMessage(EncodeMessage(m, kTag), kTag);
    ASSERT_TRUE(back.ok()) << back.error().ToString();
    EXPECT_EQ(*back, m) << MessageTypeName(m.type);
  }
  auto back = DecodeMessage(EncodeMessage(Sample(), kTag), kTag);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(*back, Sample());
}

TEST(MessageCodec, HeartbeatIsCompact) {
  Message m;
  m.type = MessageType::kHeartbeat;
  m.from = 1;
  m.to = 2;
  m.term = 12;
  m.commit = 300;
  EXPECT_LE(EncodeMessage(m, kTag).size(), 20u);
}

TEST(MessageCodec, RejectsOtherVersionWithReason) {
  Bytes b = EncodeMessage(Sample(), kTag);
  b[0] = 2;
  auto r = DecodeMessage(b, kTag);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code(), ErrorCode::kProtocol);
  EXPECT_NE(r.error().message().find("unsupported wire version 2 (expected 1)"), std::string::npos);
}

TEST(MessageCodec, RejectsOtherClusterWithReason) {
  auto r = DecodeMessage(EncodeMessage(Sample(), kTag), kTag + 1);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message().find("member lists differ"), std::string::npos);
}

TEST(MessageCodec, RejectsTruncationAndTrailingBytes) {
  const Bytes b = EncodeMessage(Sample(), kTag);
  for (std::size_t n = 0; n < b.size(); ++n) {
    auto r = DecodeMessage(std::span<const std::uint8_t>(b.data(), n), kTag);
    ASSERT_FALSE(r.ok()) << n;
  }
  Bytes longer = b;
  longer.push_back(0);
  auto r = DecodeMessage(longer, kTag);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message().find("trailing bytes"), std::string::npos);
}

TEST(MessageCodec, RejectsNonContiguousAppend) {
  Message m = Sample();
  m.entries[1].index = 45;
  auto r = DecodeMessage(EncodeMessage(m, kTag), kTag);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message().find("not contiguous"), std::string::npos);
}

TEST(MessageCodec, ClusterTagDependsOnMembers) {
  EXPECT_EQ(ClusterTag({"a", "b"}), ClusterTag({"a", "b"}));
  EXPECT_NE(ClusterTag({"a", "b"}), ClusterTag({"a", "c"}));
  EXPECT_NE(ClusterTag({"ab"}), ClusterTag({"a", "b"}));
}

// Seeded random bytes, and random mutations of valid messages, never crash: they decode or they
// return an error.
TEST(MessageCodec, RandomBytesNeverCrash) {
  std::mt19937_64 rng(20240611);
  int errors = 0, decoded = 0;
  const Bytes valid = EncodeMessage(Sample(), kTag);
  for (int i = 0; i < 200000; ++i) {
    Bytes b;
    if (i % 2 == 0) {
      b.resize(rng() % 64);
      for (auto& x : b) x = static_cast<std::uint8_t>(rng());
      if (!b.empty() && i % 4 == 0) b[0] = kWireVersion;
    } else {
      b = valid;
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int f = 0; f < flips; ++f) b[rng() % b.size()] = static_cast<std::uint8_t>(rng());
      if (rng() % 3 == 0) b.resize(rng() % (b.size() + 1));
    }
    auto r = DecodeMessage(b, kTag);
    if (r.ok()) {
      ++decoded;
      EXPECT_FALSE(IsLocalMessage(r->type));
    } else {
      ++errors;
      EXPECT_FALSE(r.error().message().empty());
    }
  }
  EXPECT_GT(errors, 100000);
  EXPECT_GT(decoded, 0);  // some mutations are still valid messages
}

}  // namespace
}  // namespace swarmbox::raft
