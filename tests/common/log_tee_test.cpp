#include "swarmbox/common/log_tee.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

namespace swarmbox {
namespace {

std::string ReadAll(std::FILE* f) {
  std::rewind(f);
  std::string text;
  char buf[256];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
  return text;
}

TEST(LogTee, PassesBytesOnAndHandsOverEachLine) {
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  std::vector<std::string> lines;
  {
    auto tee = LogTee::Create(out, [&](std::string_view line) { lines.emplace_back(line); });
    ASSERT_TRUE(tee) << tee.error().ToString();
    std::fprintf((*tee)->file(), "t=1.000 node=a event=x\n");
    // A line written in pieces (no flush between) is one line.
    std::fprintf((*tee)->file(), "t=2.000 node=a ");
    std::fprintf((*tee)->file(), "event=y k=\"v w\"\nt=3.000 node=a event=z\n");
    EXPECT_EQ(ReadAll(out), "t=1.000 node=a event=x\nt=2.000 node=a event=y k=\"v w\"\nt=3.000 node=a event=z\n");
    std::fprintf((*tee)->file(), "no newline yet");
  }
  // The last line, without its '\n', when the tee goes.
  EXPECT_EQ(ReadAll(out), "t=1.000 node=a event=x\nt=2.000 node=a event=y k=\"v w\"\nt=3.000 node=a event=z\nno newline yet");
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], "t=1.000 node=a event=x");
  EXPECT_EQ(lines[1], "t=2.000 node=a event=y k=\"v w\"");
  EXPECT_EQ(lines[2], "t=3.000 node=a event=z");
  EXPECT_EQ(lines[3], "no newline yet");
  std::fclose(out);
}

}  // namespace
}  // namespace swarmbox
