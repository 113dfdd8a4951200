// The independent check, both ways. Recordings written by McapWriter are read by @mcap/core, the
// TypeScript reference implementation, through tests/js/verify_mcap.mjs (node): its channels,
// counts, time range, compression and chunks must match what was written, for every compression,
// and a corrupted recording must make it fail. And files written by @mcap/core's own McapWriter
// (tests/js/write_mcap_sample.mjs) are read by McapReader: the same messages in log-time order.
// Needs node and `npm ci` in tests/js (scripts/setup.sh does both).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "mcap_test_util.hpp"
#include "support/child_process.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/record/foxglove_schemas.hpp"
#include "swarmbox/record/mcap.hpp"

namespace swarmbox::record {
namespace {

constexpr const char* kNode = SWARMBOX_NODE;      // find_program(node) at configure time
constexpr const char* kJsDir = SWARMBOX_JS_DIR;   // the source tree's tests/js

struct Expected {
  std::map<std::string, std::pair<std::string, int>> channels;  // topic -> (schema, count)
  std::map<std::string, std::pair<std::uint64_t, std::uint64_t>> range;
  int total = 0;
};

// A recording shaped like a trial's: the contract's channels for three drones over 20 simulated
// seconds at 10 Hz, the world once, logs, and camera frames of a few kB of base64.
Expected WriteTrialLike(const std::string& path, Compression compression) {
  McapOptions options;
  options.compression = compression;
  options.chunk_bytes = 32 << 10;  // many chunks
  auto writer = McapWriter::Create(path, options);
  EXPECT_TRUE(writer) << writer.error().ToString();
  Expected e;
  auto add = [&](const std::string& topic, std::string_view schema) {
    auto id = (*writer)->AddChannel(MakeChannel(topic, schema));
    EXPECT_TRUE(id);
    e.channels[topic] = {std::string(schema), 0};
    return *id;
  };
  auto write = [&](ChannelId id, const std::string& topic, std::uint64_t t, const std::string& json) {
    EXPECT_TRUE((*writer)->Write(id, t, json));
    auto& [schema, count] = e.channels[topic];
    if (count == 0) e.range[topic].first = t;
    e.range[topic].second = t;
    ++count;
    ++e.total;
  };
  const ChannelId world = add("/world", kSceneUpdate);
  const ChannelId tf = add("/tf", kFrameTransforms);
  const ChannelId log = add("/log", kLog);
  write(world, "/world", 0,
        R"({"deletions":[],"entities":[{"timestamp":{"sec":0,"nsec":0},"frame_id":"world","id":"ground",)"
        R"("cubes":[{"pose":{"position":{"x":0,"y":0,"z":0},"orientation":{"x":0,"y":0,"z":0,"w":1}},)"
        R"("size":{"x":100,"y":100,"z":0.1},"color":{"r":0.3,"g":0.5,"b":0.3,"a":1}}]}]})");
  const std::vector<std::string> drones = {"scout_1", "scout_2", "lifter_1"};
  std::map<std::string, ChannelId> truth, camera;
  for (const std::string& d : drones) {
    truth[d] = add("/drones/" + d + "/truth", kDroneTruth);
    camera[d] = add("/drones/" + d + "/camera", kCompressedImage);
  }
  const std::string jpeg_b64(6000, 'A');
  for (std::uint64_t step = 1; step <= 200; ++step) {
    const std::uint64_t t = step * 100'000'000;  // 10 Hz
    const std::string ts = JsonTimestamp(t);
    std::string transforms;
    for (const std::string& d : drones) {
      write(truth[d], "/drones/" + d + "/truth", t,
            R"({"timestamp":)" + ts + R"(,"drone":")" + d + R"(","position":[1,2,)" + std::to_string(step) +
                R"(],"velocity":[0,0,1],"orientation":{"x":0,"y":0,"z":0,"w":1}})");
      if (step % 10 == 0) {
        write(camera[d], "/drones/" + d + "/camera", t,
              R"({"timestamp":)" + ts + R"(,"frame_id":")" + d + R"(","format":"jpeg","data":")" + jpeg_b64 + R"("})");
      }
      transforms += std::string(transforms.empty() ? "" : ",") + R"({"timestamp":)" + ts +
                    R"(,"parent_frame_id":"world","child_frame_id":")" + d + R"(","translation":{"x":1,"y":2,"z":3},)"
                    R"("rotation":{"x":0,"y":0,"z":0,"w":1}})";
    }
    write(tf, "/tf", t, R"({"transforms":[)" + transforms + "]}");
    if (step % 7 == 0) {
      write(log, "/log", t, R"({"timestamp":)" + ts + R"(,"level":2,"name":"scout_1","message":"event=tick step=)" +
                                std::to_string(step) + R"(","file":"","line":0})");
    }
  }
  EXPECT_TRUE((*writer)->Close());
  return e;
}

class McapNodeTest : public testing::TempDirTest, public ::testing::WithParamInterface<Compression> {
 protected:
  void SetUp() override {
    testing::TempDirTest::SetUp();
    ASSERT_TRUE(std::filesystem::exists(kNode))
        << "node not found at configure time (" << kNode << "): install nodejs (bash scripts/setup.sh), re-run cmake";
    ASSERT_TRUE(std::filesystem::exists(std::string(kJsDir) + "/node_modules/@mcap/core"))
        << "the JS test packages are missing: run (cd " << kJsDir << " && npm ci)";
  }

  Result<swarmbox::testing::Finished> Verify(const std::string& path) {
    return swarmbox::testing::RunToEnd({kNode, std::string(kJsDir) + "/verify_mcap.mjs", path},
                                       std::chrono::seconds(120), dir_);
  }
};

TEST_P(McapNodeTest, McapCoreReadsWhatTheWriterWrote) {
  const std::string path = Path("recording.mcap");
  const Expected expected = WriteTrialLike(path, GetParam());
  auto ours = McapReader::Open(path);
  ASSERT_TRUE(ours) << ours.error().ToString();

  auto run = Verify(path);
  ASSERT_TRUE(run) << run.error().ToString();
  ASSERT_EQ(run->code, 0) << run->err;
  auto doc = yaml::Parse(run->out, "verify_mcap output");
  ASSERT_TRUE(doc) << doc.error().ToString() << "\n" << run->out;
  auto integer = [](const yaml::Node* n) { return n == nullptr ? -1 : n->AsInt().value_or(-1); };

  EXPECT_EQ(integer(doc->Find("message_count")), expected.total);
  EXPECT_EQ(integer(doc->Find("start_ns")), 0);
  EXPECT_EQ(integer(doc->Find("end_ns")), 20'000'000'000);
  EXPECT_EQ(integer(doc->Find("chunks")), static_cast<std::int64_t>(ours->chunk_count()));
  EXPECT_GT(integer(doc->Find("chunks")), 3);
  EXPECT_EQ(doc->Find("library")->scalar(), ours->library());
  const yaml::Node* compression = doc->Find("compression");
  ASSERT_EQ(compression->items().size(), 1u);
  EXPECT_EQ(compression->items()[0].scalar(), GetParam() == Compression::kNone ? "" : CompressionName(GetParam()));

  const yaml::Node* channels = doc->Find("channels");
  ASSERT_NE(channels, nullptr);
  ASSERT_EQ(channels->items().size(), expected.channels.size());
  for (const yaml::Node& c : channels->items()) {
    const std::string topic = c.Find("topic")->scalar();
    SCOPED_TRACE(topic);
    ASSERT_EQ(expected.channels.count(topic), 1u);
    const auto& [schema, count] = expected.channels.at(topic);
    EXPECT_EQ(c.Find("schema_name")->scalar(), schema);
    EXPECT_EQ(c.Find("schema_encoding")->scalar(), "jsonschema");
    EXPECT_EQ(c.Find("message_encoding")->scalar(), "json");
    EXPECT_EQ(integer(c.Find("count")), count);
    EXPECT_EQ(integer(c.Find("first_ns")), static_cast<std::int64_t>(expected.range.at(topic).first));
    EXPECT_EQ(integer(c.Find("last_ns")), static_cast<std::int64_t>(expected.range.at(topic).second));
  }
}

INSTANTIATE_TEST_SUITE_P(EveryCompression, McapNodeTest,
                         ::testing::Values(Compression::kZstd, Compression::kLz4, Compression::kNone),
                         [](const auto& p) { return std::string(CompressionName(p.param)); });

TEST_F(McapNodeTest, McapCoreReadsAnEmptyRecording) {
  const std::string path = Path("empty.mcap");
  {
    auto writer = McapWriter::Create(path);
    ASSERT_TRUE(writer);
    ASSERT_TRUE((*writer)->AddChannel(MakeChannel("/log", kLog)));  // a channel, no messages
    ASSERT_TRUE((*writer)->Close());
  }
  auto run = Verify(path);
  ASSERT_TRUE(run) << run.error().ToString();
  ASSERT_EQ(run->code, 0) << run->err;
  auto doc = yaml::Parse(run->out, "verify_mcap output");
  ASSERT_TRUE(doc) << doc.error().ToString();
  EXPECT_EQ(doc->Find("message_count")->scalar(), "0");
  EXPECT_EQ(doc->Find("chunks")->scalar(), "0");
  ASSERT_EQ(doc->Find("channels")->items().size(), 1u);
  EXPECT_EQ(doc->Find("channels")->items()[0].Find("count")->scalar(), "0");
}

TEST_F(McapNodeTest, McapCoreRejectsACorruptedRecording) {
  const std::string path = Path("recording.mcap");
  WriteTrialLike(path, Compression::kNone);
  std::string bytes = swarmbox::testing::ReadWholeFile(path);
  const std::size_t at = bytes.find("event=tick step=14");
  ASSERT_NE(at, std::string::npos);
  bytes[at + 16] = '9';
  testing::WriteFile(path, bytes);
  auto run = Verify(path);
  ASSERT_TRUE(run) << run.error().ToString();
  EXPECT_EQ(run->code, 1);
  EXPECT_NE(run->err.find("CRC"), std::string::npos) << run->err;
}

class McapForeignFileTest : public McapNodeTest {};

TEST_P(McapForeignFileTest, McapReaderReadsWhatMcapCoreWrote) {
  const std::string path = Path("foreign.mcap");
  const std::string compression = GetParam() == Compression::kLz4 ? "lz4" : "none";
  auto run = swarmbox::testing::RunToEnd(
      {kNode, std::string(kJsDir) + "/write_mcap_sample.mjs", path, compression}, std::chrono::seconds(120), dir_);
  ASSERT_TRUE(run) << run.error().ToString();
  ASSERT_EQ(run->code, 0) << run->err;
  auto doc = yaml::Parse(run->out, "write_mcap_sample output");
  ASSERT_TRUE(doc) << doc.error().ToString();

  auto reader = McapReader::Open(path);
  ASSERT_TRUE(reader) << reader.error().ToString();
  EXPECT_EQ(reader->library(), "@mcap/core sample");
  EXPECT_GT(reader->chunk_count(), 5u);
  const auto& channels = doc->Find("channels")->items();
  ASSERT_EQ(reader->channels().size(), channels.size());
  for (std::size_t i = 0; i < channels.size(); ++i) {
    EXPECT_EQ(reader->channels()[i].topic, channels[i].Find("topic")->scalar());
    EXPECT_EQ(reader->channels()[i].schema_name, channels[i].Find("schema_name")->scalar());
    EXPECT_NE(reader->channels()[i].schema.find("\"integer\""), std::string::npos);
  }

  struct Row {
    ChannelId channel;
    std::uint64_t t;
    std::string data;
  };
  std::vector<Row> expected;
  for (const yaml::Node& m : doc->Find("messages")->items()) {
    expected.push_back({static_cast<ChannelId>(m.items()[0].AsInt().value_or(-1)),
                        static_cast<std::uint64_t>(m.items()[1].AsInt().value_or(-1)), m.items()[2].scalar()});
  }
  ASSERT_EQ(expected.size(), 600u);
  EXPECT_EQ(reader->message_count(), expected.size());
  std::stable_sort(expected.begin(), expected.end(), [](const Row& a, const Row& b) { return a.t < b.t; });
  std::vector<Row> read;
  Status s = reader->ForEach([&](const McapMessage& m) { read.push_back({m.channel, m.log_time_ns, m.data}); });
  ASSERT_TRUE(s) << s.error().ToString();
  ASSERT_EQ(read.size(), expected.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    SCOPED_TRACE("message " + std::to_string(i));
    EXPECT_EQ(read[i].channel, expected[i].channel);
    EXPECT_EQ(read[i].t, expected[i].t);
    EXPECT_EQ(read[i].data, expected[i].data);
  }
}

INSTANTIATE_TEST_SUITE_P(Lz4AndNone, McapForeignFileTest, ::testing::Values(Compression::kLz4, Compression::kNone),
                         [](const auto& p) { return std::string(CompressionName(p.param)); });

}  // namespace
}  // namespace swarmbox::record
