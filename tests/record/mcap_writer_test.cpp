// McapWriter against the spec's file layout (https://mcap.dev/spec), read byte by byte here.
#include <gtest/gtest.h>

#include <zlib.h>

#include <string>

#include "mcap_test_util.hpp"
#include "swarmbox/record/mcap.hpp"

namespace swarmbox::record {
namespace {

using testing::Le;
using testing::TopLevelRecords;
using testing::TopRecord;

constexpr std::string_view kMagic{"\x89MCAP0\r\n", 8};

std::uint32_t Crc(std::string_view bytes) {
  return static_cast<std::uint32_t>(
      crc32(0, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(bytes.size())));
}

class McapWriterTest : public testing::TempDirTest {
 protected:
  std::string WriteSample(McapOptions options) {
    const std::string path = Path("sample.mcap");
    auto writer = McapWriter::Create(path, options);
    EXPECT_TRUE(writer) << writer.error().ToString();
    auto a = (*writer)->AddChannel({"/a", "swarmbox.A", R"({"type":"object"})"});
    auto b = (*writer)->AddChannel({"/b", "swarmbox.A", R"({"type":"object"})"});  // same schema
    EXPECT_TRUE(a && b);
    for (std::uint64_t i = 0; i < 10; ++i) {
      EXPECT_TRUE((*writer)->Write(*a, 1000 + i, R"({"i":)" + std::to_string(i) + "}"));
      EXPECT_TRUE((*writer)->Write(*b, 2000 + i, R"({"j":1})"));
    }
    EXPECT_TRUE((*writer)->Close());
    return swarmbox::testing::ReadWholeFile(path);
  }
};

TEST_F(McapWriterTest, FileHasTheSpecLayoutWithChunksIndexesSummaryAndFooter) {
  McapOptions options;
  options.chunk_bytes = 200;  // several chunks
  const std::string file = WriteSample(options);
  ASSERT_GT(file.size(), 16u);
  EXPECT_EQ(std::string_view(file).substr(0, 8), kMagic);
  EXPECT_EQ(std::string_view(file).substr(file.size() - 8), kMagic);

  const std::vector<TopRecord> records = TopLevelRecords(file);
  ASSERT_FALSE(records.empty());
  EXPECT_EQ(records.front().op, 0x01);  // Header
  EXPECT_EQ(records.back().op, 0x02);   // Footer
  // Header: profile "" and the library.
  EXPECT_EQ(Le(records.front().content, 0, 4), 0u);
  EXPECT_NE(std::string(records.front().content).find("swarmbox"), std::string::npos);

  // Data section: Schema once, two Channels, then Chunk followed by its MessageIndexes, DataEnd.
  std::size_t i = 1;
  EXPECT_EQ(records[i++].op, 0x03);
  EXPECT_EQ(records[i++].op, 0x04);
  EXPECT_EQ(records[i++].op, 0x04);
  int chunks = 0;
  while (records[i].op == 0x06) {
    ++chunks;
    ++i;
    ASSERT_EQ(records[i].op, 0x07) << "a chunk is followed by its message indexes";
    while (records[i].op == 0x07) ++i;
  }
  EXPECT_GT(chunks, 1);
  ASSERT_EQ(records[i].op, 0x0F);  // DataEnd
  const TopRecord& data_end = records[i];
  EXPECT_EQ(Le(data_end.content, 0, 4), Crc(std::string_view(file).substr(0, data_end.offset)));
  ++i;

  // Summary grouped by opcode: Schema, Channel, Statistics, ChunkIndex; then SummaryOffsets.
  const std::uint64_t summary_start = records[i].offset;
  std::vector<std::uint8_t> summary_ops;
  for (; records[i].op != 0x0E; ++i) summary_ops.push_back(records[i].op);
  EXPECT_EQ(summary_ops.front(), 0x03);
  const std::uint64_t summary_offset_start = records[i].offset;
  int chunk_indexes = 0;
  for (std::uint8_t op : summary_ops) chunk_indexes += op == 0x08 ? 1 : 0;
  EXPECT_EQ(chunk_indexes, chunks);
  int offsets = 0;
  for (; records[i].op == 0x0E; ++i) {
    ++offsets;
    const std::uint8_t group = static_cast<std::uint8_t>(records[i].content[0]);
    const std::uint64_t start = Le(records[i].content, 1, 8);
    EXPECT_EQ(static_cast<std::uint8_t>(file[start]), group) << "a group starts with its opcode";
  }
  EXPECT_EQ(offsets, 4);  // Schema, Channel, Statistics, ChunkIndex

  // Footer: offsets and the CRC of the summary through summary_offset_start.
  const TopRecord& footer = records.back();
  EXPECT_EQ(Le(footer.content, 0, 8), summary_start);
  EXPECT_EQ(Le(footer.content, 8, 8), summary_offset_start);
  EXPECT_EQ(Le(footer.content, 16, 4),
            Crc(std::string_view(file).substr(summary_start, footer.offset + 9 + 16 - summary_start)));
}

TEST_F(McapWriterTest, ChunkIndexPointsAtItsChunkAndMessageIndexes) {
  McapOptions options;
  options.compression = Compression::kNone;
  const std::string file = WriteSample(options);
  for (const TopRecord& r : TopLevelRecords(file)) {
    if (r.op != 0x08) continue;
    const std::uint64_t chunk_at = Le(r.content, 16, 8);
    const std::uint64_t chunk_length = Le(r.content, 24, 8);
    EXPECT_EQ(static_cast<std::uint8_t>(file[chunk_at]), 0x06);
    EXPECT_EQ(9 + Le(file, chunk_at + 1, 8), chunk_length);
    const std::uint64_t map_bytes = Le(r.content, 32, 4);
    EXPECT_EQ(map_bytes, 2u * 10u);  // both channels have messages in the one chunk
    for (std::uint64_t at = 36; at < 36 + map_bytes; at += 10) {
      const std::uint64_t index_at = Le(r.content, at + 2, 8);
      EXPECT_EQ(static_cast<std::uint8_t>(file[index_at]), 0x07);
      EXPECT_EQ(Le(file, index_at + 9, 2), Le(r.content, at, 2)) << "the index is the channel's";
    }
    // Message index entries: offsets into the uncompressed records point at Message records.
    const std::uint64_t records_at = chunk_at + 9 + 8 + 8 + 8 + 4 + 4 + 8;  // compression ""
    const std::uint64_t index_at = Le(r.content, 36 + 2, 8);
    const std::uint64_t entries = Le(file, index_at + 11, 4) / 16;
    EXPECT_EQ(entries, 10u);
    for (std::uint64_t e = 0; e < entries; ++e) {
      const std::uint64_t offset = Le(file, index_at + 15 + 16 * e + 8, 8);
      EXPECT_EQ(static_cast<std::uint8_t>(file[records_at + offset]), 0x05);
    }
  }
}

TEST_F(McapWriterTest, WritesAfterCloseAndOnUnknownChannelsFail) {
  auto writer = McapWriter::Create(Path("x.mcap"));
  ASSERT_TRUE(writer);
  auto bad = (*writer)->Write(3, 0, "{}");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message().find("unknown channel 3"), std::string::npos);
  auto id = (*writer)->AddChannel({"/t", "s", "{}"});
  ASSERT_TRUE(id);
  ASSERT_TRUE((*writer)->Close());
  auto late = (*writer)->Write(*id, 0, "{}");
  ASSERT_FALSE(late);
  EXPECT_NE(late.error().message().find("after Close"), std::string::npos);
  EXPECT_TRUE((*writer)->Close()) << "closing twice is harmless";
}

TEST_F(McapWriterTest, AddingTheSameChannelTwiceGivesTheSameId) {
  auto writer = McapWriter::Create(Path("x.mcap"));
  ASSERT_TRUE(writer);
  auto a = (*writer)->AddChannel({"/t", "s", "{}"});
  auto b = (*writer)->AddChannel({"/t", "s", "{}"});
  auto c = (*writer)->AddChannel({"/u", "s", "{}"});
  ASSERT_TRUE(a && b && c);
  EXPECT_EQ(*a, *b);
  EXPECT_NE(*a, *c);
}

TEST_F(McapWriterTest, CreateInAMissingFolderFailsWithThePath) {
  auto writer = McapWriter::Create(Path("no/such/dir/x.mcap"));
  ASSERT_FALSE(writer);
  EXPECT_EQ(writer.error().code(), ErrorCode::kIo);
  EXPECT_NE(writer.error().where().find("no/such/dir/x.mcap"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::record
