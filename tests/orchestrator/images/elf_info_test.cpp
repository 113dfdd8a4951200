#include "swarmbox/images/elf_info.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "swarmbox/images/library_closure.hpp"

namespace swarmbox::images {
namespace {

bool Contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

TEST(ElfInfo, ReadsTheInterpreterAndNeededLibrariesOfTheProbe) {
  auto bytes = ReadFileBytes(SWARMBOX_PROBE_PATH);
  ASSERT_TRUE(bytes) << bytes.error().ToString();
  auto info = ReadElfInfo(*bytes, SWARMBOX_PROBE_PATH);
  ASSERT_TRUE(info) << info.error().ToString();
  EXPECT_TRUE(info->is_64);
  EXPECT_TRUE(info->dynamic);
  EXPECT_EQ(info->interpreter, "/lib64/ld-linux-x86-64.so.2");
  EXPECT_TRUE(Contains(info->needed, "libstdc++.so.6"));
  EXPECT_TRUE(Contains(info->needed, "libc.so.6"));
}

TEST(ElfInfo, ReadsTheSonameOfASharedLibrary) {
  auto bytes = ReadFileBytes("/lib/x86_64-linux-gnu/libc.so.6");
  ASSERT_TRUE(bytes) << bytes.error().ToString();
  auto info = ReadElfInfo(*bytes, "libc");
  ASSERT_TRUE(info) << info.error().ToString();
  EXPECT_EQ(info->kind, ElfInfo::Kind::kSharedObject);
  EXPECT_EQ(info->soname, "libc.so.6");
}

TEST(ElfInfo, RejectsNonElfAndTruncatedInput) {
  auto text = ReadElfInfo("#!/bin/sh\necho hi\n", "script.sh");
  ASSERT_FALSE(text);
  EXPECT_EQ(text.error().ToString(), "script.sh: not a usable ELF file: no ELF magic");
  auto bytes = ReadFileBytes(SWARMBOX_PROBE_PATH);
  ASSERT_TRUE(bytes);
  auto cut = ReadElfInfo(std::string_view(*bytes).substr(0, 200), "cut");
  ASSERT_FALSE(cut);
  EXPECT_NE(cut.error().message().find("out of bounds"), std::string::npos) << cut.error().message();
}

TEST(LibraryClosure, IncludesTheLoaderAndLibstdcxxOfTheProbe) {
  auto closure = SharedLibraryClosure({SWARMBOX_PROBE_PATH});
  ASSERT_TRUE(closure) << closure.error().ToString();
  EXPECT_TRUE(Contains(*closure, "/lib64/ld-linux-x86-64.so.2"));
  EXPECT_TRUE(Contains(*closure, "/lib/x86_64-linux-gnu/libc.so.6"));
  EXPECT_TRUE(std::any_of(closure->begin(), closure->end(), [](const std::string& p) {
    return p.find("libstdc++.so.6") != std::string::npos;
  }));
}

TEST(LibraryClosure, NamesAMissingInput) {
  auto closure = SharedLibraryClosure({"/nonexistent/swarmbox-agent"});
  ASSERT_FALSE(closure);
  EXPECT_EQ(closure.error().code(), ErrorCode::kNotFound);
  EXPECT_EQ(closure.error().where(), "/nonexistent/swarmbox-agent");
}

}  // namespace
}  // namespace swarmbox::images
