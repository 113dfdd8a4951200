// McapWriter -> McapReader round trips: every compression, empty files, many channels, chunk
// boundaries, log-time order, and the corruptions the CRCs must catch.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "mcap_test_util.hpp"
#include "swarmbox/record/mcap.hpp"

namespace swarmbox::record {
namespace {

using testing::Le;
using testing::TopLevelRecords;

struct Written {
  ChannelId channel;
  std::uint64_t t;
  std::string data;
};

class McapReaderTest : public testing::TempDirTest {
 protected:
  // Writes `messages` on `channels` (topics /c<i>), returns the path.
  std::string Write(const std::vector<Written>& messages, std::size_t channels, McapOptions options = {}) {
    const std::string path = Path("r.mcap");
    auto writer = McapWriter::Create(path, options);
    EXPECT_TRUE(writer) << writer.error().ToString();
    for (std::size_t i = 0; i < channels; ++i) {
      auto id = (*writer)->AddChannel({"/c" + std::to_string(i), "swarmbox.S" + std::to_string(i % 3),
                                       R"({"type":"object","n":)" + std::to_string(i % 3) + "}"});
      EXPECT_TRUE(id);
      EXPECT_EQ(*id, i);
    }
    for (const Written& m : messages) EXPECT_TRUE((*writer)->Write(m.channel, m.t, m.data));
    EXPECT_TRUE((*writer)->Close());
    return path;
  }

  static std::vector<McapMessage> ReadAll(const McapReader& reader) {
    std::vector<McapMessage> out;
    Status s = reader.ForEach([&](const McapMessage& m) { out.push_back(m); });
    EXPECT_TRUE(s) << s.error().ToString();
    return out;
  }
};

class McapCompressionTest : public McapReaderTest, public ::testing::WithParamInterface<Compression> {};

TEST_P(McapCompressionTest, RoundTripKeepsChannelsMessagesAndTimes) {
  std::vector<Written> messages;
  for (std::uint64_t i = 0; i < 2000; ++i) {
    messages.push_back({static_cast<ChannelId>(i % 3), 1'000'000'000 + i * 10'000'000,
                        R"({"timestamp":{"sec":1,"nsec":0},"i":)" + std::to_string(i) + R"(,"pad":"xxxxxxxxxxxx"})"});
  }
  McapOptions options;
  options.compression = GetParam();
  options.chunk_bytes = 16 << 10;
  const std::string path = Write(messages, 3, options);

  auto reader = McapReader::Open(path);
  ASSERT_TRUE(reader) << reader.error().ToString();
  ASSERT_EQ(reader->channels().size(), 3u);
  EXPECT_EQ(reader->channels()[1].topic, "/c1");
  EXPECT_EQ(reader->channels()[1].schema_name, "swarmbox.S1");
  EXPECT_EQ(reader->channels()[1].schema, R"({"type":"object","n":1})");
  EXPECT_EQ(reader->message_count(), 2000u);
  EXPECT_EQ(reader->start_ns(), 1'000'000'000u);
  EXPECT_EQ(reader->end_ns(), 1'000'000'000ull + 1999ull * 10'000'000ull);
  EXPECT_EQ(reader->profile(), "");
  EXPECT_GT(reader->chunk_count(), 1u);

  const std::vector<McapMessage> read = ReadAll(*reader);
  ASSERT_EQ(read.size(), messages.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].channel, messages[i].channel);
    EXPECT_EQ(read[i].log_time_ns, messages[i].t);
    EXPECT_EQ(read[i].data, messages[i].data);
  }
}

INSTANTIATE_TEST_SUITE_P(EveryCompression, McapCompressionTest,
                         ::testing::Values(Compression::kZstd, Compression::kLz4, Compression::kNone),
                         [](const auto& p) { return std::string(CompressionName(p.param)); });

TEST_F(McapReaderTest, CompressionShrinksRepetitiveJson) {
  std::vector<Written> messages;
  for (std::uint64_t i = 0; i < 5000; ++i) {
    messages.push_back({0, i, R"({"timestamp":{"sec":0,"nsec":)" + std::to_string(i) +
                                  R"(},"drone":"scout_1","position":[1.5,2.5,30.0]})"});
  }
  std::map<Compression, std::uintmax_t> sizes;
  for (Compression c : {Compression::kNone, Compression::kLz4, Compression::kZstd}) {
    McapOptions options;
    options.compression = c;
    sizes[c] = std::filesystem::file_size(Write(messages, 1, options));
  }
  EXPECT_LT(sizes[Compression::kLz4] * 3, sizes[Compression::kNone]);
  EXPECT_LT(sizes[Compression::kZstd], sizes[Compression::kLz4]);
}

TEST_F(McapReaderTest, EmptyRecordingOpensWithNoMessages) {
  const std::string path = Write({}, 0);
  auto reader = McapReader::Open(path);
  ASSERT_TRUE(reader) << reader.error().ToString();
  EXPECT_TRUE(reader->channels().empty());
  EXPECT_EQ(reader->message_count(), 0u);
  EXPECT_EQ(reader->start_ns(), 0u);
  EXPECT_EQ(reader->end_ns(), 0u);
  EXPECT_EQ(reader->chunk_count(), 0u);
  EXPECT_TRUE(ReadAll(*reader).empty());
}

TEST_F(McapReaderTest, ChannelsWithoutMessagesAreListed) {
  const std::string path = Write({{1, 5, "{}"}}, 4);
  auto reader = McapReader::Open(path);
  ASSERT_TRUE(reader);
  EXPECT_EQ(reader->channels().size(), 4u);
  const auto read = ReadAll(*reader);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].channel, 1u);
}

TEST_F(McapReaderTest, ManyChannelsKeepTheirCounts) {
  constexpr std::size_t kChannels = 600;
  std::vector<Written> messages;
  for (std::uint64_t i = 0; i < 6000; ++i) {
    const auto c = static_cast<ChannelId>((i * 7) % kChannels);
    messages.push_back({c, i, "{\"c\":" + std::to_string(c) + "}"});
  }
  McapOptions options;
  options.chunk_bytes = 8 << 10;
  auto reader = McapReader::Open(Write(messages, kChannels, options));
  ASSERT_TRUE(reader) << reader.error().ToString();
  ASSERT_EQ(reader->channels().size(), kChannels);
  EXPECT_EQ(reader->channels()[599].topic, "/c599");
  std::vector<int> counts(kChannels, 0);
  for (const McapMessage& m : ReadAll(*reader)) {
    ++counts[m.channel];
    EXPECT_EQ(m.data, "{\"c\":" + std::to_string(m.channel) + "}");
  }
  for (std::size_t c = 0; c < kChannels; ++c) EXPECT_EQ(counts[c], 10) << "channel " << c;
}

TEST_F(McapReaderTest, MessagesComeBackInLogTimeOrderAcrossChunksTiesInFileOrder) {
  // Times go back and forth across chunk boundaries (a late message for an early time), with ties.
  std::vector<Written> messages;
  for (std::uint64_t i = 0; i < 400; ++i) {
    const std::uint64_t t = (i % 2 == 0) ? i : 400 - i;
    messages.push_back({static_cast<ChannelId>(i % 2), t / 4 * 4, std::to_string(i)});
  }
  McapOptions options;
  options.chunk_bytes = 300;  // ~10 messages a chunk
  auto reader = McapReader::Open(Write(messages, 2, options));
  ASSERT_TRUE(reader);
  EXPECT_GT(reader->chunk_count(), 20u);
  const auto read = ReadAll(*reader);
  ASSERT_EQ(read.size(), messages.size());
  std::vector<std::size_t> expected(messages.size());
  for (std::size_t i = 0; i < expected.size(); ++i) expected[i] = i;
  std::stable_sort(expected.begin(), expected.end(),
                   [&](std::size_t a, std::size_t b) { return messages[a].t < messages[b].t; });
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].data, std::to_string(expected[i])) << "position " << i;
  }
}

TEST_F(McapReaderTest, OneMessageLargerThanAChunkGetsItsOwnChunk) {
  const std::string big(3 << 20, 'x');
  McapOptions options;
  options.chunk_bytes = 1 << 20;
  auto reader = McapReader::Open(Write({{0, 1, "small"}, {0, 2, big}, {0, 3, "after"}}, 1, options));
  ASSERT_TRUE(reader);
  EXPECT_EQ(reader->chunk_count(), 2u);
  const auto read = ReadAll(*reader);
  ASSERT_EQ(read.size(), 3u);
  EXPECT_EQ(read[1].data.size(), big.size());
  EXPECT_EQ(read[2].data, "after");
}

TEST_F(McapReaderTest, WritersOnSeveralThreadsLoseNothing) {
  const std::string path = Path("threads.mcap");
  McapOptions options;
  options.chunk_bytes = 4 << 10;
  auto writer = McapWriter::Create(path, options);
  ASSERT_TRUE(writer);
  std::vector<std::thread> threads;
  for (int k = 0; k < 4; ++k) {
    threads.emplace_back([&, k] {
      auto id = (*writer)->AddChannel({"/t" + std::to_string(k), "s", "{}"});
      ASSERT_TRUE(id);
      for (std::uint64_t i = 0; i < 2000; ++i) ASSERT_TRUE((*writer)->Write(*id, i, "{\"k\":" + std::to_string(k) + "}"));
    });
  }
  for (std::thread& t : threads) t.join();
  ASSERT_TRUE((*writer)->Close());
  auto reader = McapReader::Open(path);
  ASSERT_TRUE(reader) << reader.error().ToString();
  ASSERT_EQ(reader->channels().size(), 4u);
  std::vector<int> counts(4, 0);
  for (const McapMessage& m : ReadAll(*reader)) {
    ++counts[m.channel];
    EXPECT_EQ(m.data, "{\"k\":" + reader->channels()[m.channel].topic.substr(2) + "}");
  }
  EXPECT_EQ(counts, std::vector<int>(4, 2000));
}

// --- corruption ---------------------------------------------------------------------------------

class McapCorruptionTest : public McapReaderTest {
 protected:
  void SetUp() override {
    McapReaderTest::SetUp();
    std::vector<Written> messages;
    for (std::uint64_t i = 0; i < 100; ++i) messages.push_back({0, i, "{\"value\":" + std::to_string(i) + "}"});
    McapOptions options;
    options.compression = Compression::kNone;  // payload bytes visible in the file
    path_ = Write(messages, 1, options);
    bytes_ = swarmbox::testing::ReadWholeFile(path_);
  }
  std::uint64_t OffsetOf(std::uint8_t op) const {
    for (const auto& r : TopLevelRecords(bytes_)) {
      if (r.op == op) return r.offset;
    }
    ADD_FAILURE() << "no record " << int{op};
    return 0;
  }
  std::string OpenError(const std::string& bytes) {
    testing::WriteFile(path_, bytes);
    auto reader = McapReader::Open(path_);
    if (reader) return "";
    EXPECT_EQ(reader.error().code(), ErrorCode::kProtocol);
    return reader.error().message();
  }
  std::string path_;
  std::string bytes_;
};

TEST_F(McapCorruptionTest, AFlippedByteInTheDataSectionFailsTheDataCrc) {
  std::string bad = bytes_;
  const std::size_t at = bad.find("\"value\":42");
  ASSERT_NE(at, std::string::npos);
  bad[at + 9] = '7';
  EXPECT_NE(OpenError(bad).find("data section CRC mismatch"), std::string::npos);
}

TEST_F(McapCorruptionTest, AFlippedByteInAChunkFailsTheChunkCrcWhenNoDataCrcIsGiven) {
  std::string bad = bytes_;
  bad[bad.find("\"value\":42") + 9] = '7';
  const std::uint64_t data_end = OffsetOf(0x0F);
  for (int i = 0; i < 4; ++i) bad[data_end + 9 + static_cast<std::uint64_t>(i)] = 0;  // "CRC not available"
  testing::WriteFile(path_, bad);
  auto reader = McapReader::Open(path_);
  ASSERT_TRUE(reader) << reader.error().ToString();
  Status s = reader->ForEach([](const McapMessage&) {});
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message().find("chunk CRC mismatch"), std::string::npos) << s.error().ToString();
}

TEST_F(McapCorruptionTest, AnAbsurdChunkSizeIsRefusedNotAllocated) {
  std::string bad = bytes_;
  const std::uint64_t chunk = OffsetOf(0x06);
  bad[chunk + 9 + 16 + 5] = 1;  // uncompressed_size += 2^40
  const std::uint64_t data_end = OffsetOf(0x0F);
  for (int i = 0; i < 4; ++i) bad[data_end + 9 + static_cast<std::uint64_t>(i)] = 0;
  testing::WriteFile(path_, bad);
  auto reader = McapReader::Open(path_);
  ASSERT_TRUE(reader) << reader.error().ToString();
  Status s = reader->ForEach([](const McapMessage&) {});
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message().find("exceeds the reader's limit"), std::string::npos) << s.error().ToString();
}

TEST_F(McapCorruptionTest, AFlippedByteInTheSummaryFailsTheSummaryCrc) {
  std::string bad = bytes_;
  const std::uint64_t summary = OffsetOf(0x0B);  // Statistics
  bad[summary + 9] = static_cast<char>(bad[summary + 9] ^ 0x01);  // message_count
  EXPECT_NE(OpenError(bad).find("summary CRC mismatch"), std::string::npos);
}

TEST_F(McapCorruptionTest, ATruncatedFileSaysItWasNotClosed) {
  EXPECT_NE(OpenError(bytes_.substr(0, bytes_.size() - 40)).find("truncated"), std::string::npos);
  EXPECT_NE(OpenError(bytes_.substr(0, 10)).find("not an MCAP file"), std::string::npos);
}

TEST_F(McapCorruptionTest, AnotherFormatIsNotAnMcapFile) {
  std::string bad = bytes_;
  bad[1] = 'X';
  EXPECT_NE(OpenError(bad).find("no MCAP0 magic"), std::string::npos);
}

TEST_F(McapCorruptionTest, AMissingFileIsAnIoError) {
  auto reader = McapReader::Open(Path("missing.mcap"));
  ASSERT_FALSE(reader);
  EXPECT_EQ(reader.error().code(), ErrorCode::kIo);
}

TEST(McapCompressionNames, ParseTheNamesTheyPrint) {
  for (Compression c : {Compression::kNone, Compression::kZstd, Compression::kLz4}) {
    auto parsed = ParseCompression(CompressionName(c));
    ASSERT_TRUE(parsed);
    EXPECT_EQ(*parsed, c);
  }
  auto bad = ParseCompression("gzip");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message().find("expected zstd, lz4 or none"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::record
