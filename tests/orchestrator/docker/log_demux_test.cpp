#include "swarmbox/docker/log_demux.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_data.hpp"

namespace swarmbox::docker {
namespace {

std::string Frame(StreamKind stream, std::string_view payload) {
  std::string f(8, '\0');
  f[0] = static_cast<char>(stream);
  const auto n = static_cast<std::uint32_t>(payload.size());
  f[4] = static_cast<char>((n >> 24) & 0xFF);
  f[5] = static_cast<char>((n >> 16) & 0xFF);
  f[6] = static_cast<char>((n >> 8) & 0xFF);
  f[7] = static_cast<char>(n & 0xFF);
  return f + std::string(payload);
}

struct Collected {
  std::vector<LogLine> lines;
  LogLineFn Fn() {
    return [this](const LogLine& l) { lines.push_back(l); };
  }
};

TEST(LogDemuxer, DecodesRecordedMultiplexedLogs) {
  // Recorded from `sh -c "echo out1; echo err1 >&2; echo out2"` on Docker 20.10.
  const std::string bytes = testing::ReadData("logs_multiplexed.bin");
  Collected c;
  LogDemuxer demux(LogDemuxer::Mode::kMultiplexed, c.Fn());
  ASSERT_TRUE(demux.Feed(bytes));
  ASSERT_TRUE(demux.Finish());
  ASSERT_EQ(c.lines.size(), 3u);
  std::vector<std::string> out, err;
  for (const LogLine& l : c.lines) (l.stream == StreamKind::kStdout ? out : err).push_back(l.text);
  EXPECT_EQ(out, (std::vector<std::string>{"out1", "out2"}));
  EXPECT_EQ(err, (std::vector<std::string>{"err1"}));
}

TEST(LogDemuxer, GivesTheSameLinesForEverySplitOfTheStream) {
  const std::string bytes = Frame(StreamKind::kStdout, "alpha\nbe") + Frame(StreamKind::kStderr, "E1\r\n") +
                            Frame(StreamKind::kStdout, "ta\ngamma\n") + Frame(StreamKind::kStdout, "tail");
  const std::vector<std::string> expected = {"alpha", "E1", "beta", "gamma", "tail"};
  for (std::size_t cut1 = 0; cut1 <= bytes.size(); ++cut1) {
    for (std::size_t cut2 = cut1; cut2 <= bytes.size(); cut2 += 3) {
      Collected c;
      LogDemuxer demux(LogDemuxer::Mode::kMultiplexed, c.Fn());
      ASSERT_TRUE(demux.Feed(std::string_view(bytes).substr(0, cut1)));
      ASSERT_TRUE(demux.Feed(std::string_view(bytes).substr(cut1, cut2 - cut1)));
      ASSERT_TRUE(demux.Feed(std::string_view(bytes).substr(cut2)));
      ASSERT_TRUE(demux.Finish());
      std::vector<std::string> texts;
      for (const LogLine& l : c.lines) texts.push_back(l.text);
      ASSERT_EQ(texts, expected) << "cuts at " << cut1 << "," << cut2;
      EXPECT_EQ(c.lines[1].stream, StreamKind::kStderr);
    }
  }
}

TEST(LogDemuxer, DeliversALineAsSoonAsItsNewlineArrives) {
  Collected c;
  LogDemuxer demux(LogDemuxer::Mode::kMultiplexed, c.Fn());
  const std::string frame = Frame(StreamKind::kStdout, "event=ready\nrest");
  ASSERT_TRUE(demux.Feed(frame));
  ASSERT_EQ(c.lines.size(), 1u);  // "rest" waits for its newline
  EXPECT_EQ(c.lines[0].text, "event=ready");
}

TEST(LogDemuxer, KeepsStdoutAndStderrPartialsApart) {
  Collected c;
  LogDemuxer demux(LogDemuxer::Mode::kMultiplexed, c.Fn());
  ASSERT_TRUE(demux.Feed(Frame(StreamKind::kStdout, "out-") + Frame(StreamKind::kStderr, "err-") +
                         Frame(StreamKind::kStdout, "end\n") + Frame(StreamKind::kStderr, "end\n")));
  ASSERT_EQ(c.lines.size(), 2u);
  EXPECT_EQ(c.lines[0].text, "out-end");
  EXPECT_EQ(c.lines[1].text, "err-end");
  EXPECT_EQ(c.lines[1].stream, StreamKind::kStderr);
}

TEST(LogDemuxer, RawModeSplitsTtyOutputIntoStdoutLines) {
  Collected c;
  LogDemuxer demux(LogDemuxer::Mode::kRaw, c.Fn());
  ASSERT_TRUE(demux.Feed("one\r\ntw"));
  ASSERT_TRUE(demux.Feed("o\nthree"));
  ASSERT_TRUE(demux.Finish());
  ASSERT_EQ(c.lines.size(), 3u);
  EXPECT_EQ(c.lines[0].text, "one");
  EXPECT_EQ(c.lines[1].text, "two");
  EXPECT_EQ(c.lines[2].text, "three");
  EXPECT_EQ(c.lines[2].stream, StreamKind::kStdout);
}

TEST(LogDemuxer, ReportsARawStreamReadAsMultiplexedAndKeepsItsText) {
  Collected c;
  LogDemuxer demux(LogDemuxer::Mode::kMultiplexed, c.Fn());
  Status s = demux.Feed("plain text output\nmore\n");
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code(), ErrorCode::kProtocol);
  EXPECT_NE(s.error().message().find("not multiplexed"), std::string::npos);
  ASSERT_TRUE(demux.Finish());
  ASSERT_EQ(c.lines.size(), 2u);
  EXPECT_EQ(c.lines[0].text, "plain text output");
}

TEST(LogDemuxer, ReportsAStreamCutInsideAFrame) {
  Collected c;
  LogDemuxer demux(LogDemuxer::Mode::kMultiplexed, c.Fn());
  std::string frame = Frame(StreamKind::kStdout, "complete\npartial");
  ASSERT_TRUE(demux.Feed(std::string_view(frame).substr(0, frame.size() - 3)));
  Status s = demux.Finish();
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message().find("3 payload bytes missing"), std::string::npos);
  ASSERT_EQ(c.lines.size(), 2u);
  EXPECT_EQ(c.lines[1].text, "part");
}

TEST(LogDemuxer, SplitsOverlongLinesAtTheLimit) {
  Collected c;
  LogDemuxer demux(LogDemuxer::Mode::kRaw, c.Fn());
  ASSERT_TRUE(demux.Feed(std::string(LogDemuxer::kMaxLineBytes + 10, 'x') + "\n"));
  ASSERT_EQ(c.lines.size(), 2u);
  EXPECT_EQ(c.lines[0].text.size(), LogDemuxer::kMaxLineBytes);
  EXPECT_EQ(c.lines[1].text.size(), 10u);
}

TEST(LineSplitter, SplitsJsonLinesAcrossChunks) {
  LineSplitter s;
  std::vector<std::string> lines;
  auto add = [&](std::string_view l) { lines.emplace_back(l); };
  s.Feed("{\"a\":1}\r\n{\"b\"", add);
  s.Feed(":2}\n{\"c\"", add);
  EXPECT_EQ(lines, (std::vector<std::string>{"{\"a\":1}", "{\"b\":2}"}));
  EXPECT_EQ(s.TakeRest(), "{\"c\"");
}

}  // namespace
}  // namespace swarmbox::docker
