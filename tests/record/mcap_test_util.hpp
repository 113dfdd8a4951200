// Shared by the MCAP tests: a temporary folder per test, little-endian field reads, and a walk over
// a file's top-level records that does not use McapReader (so the writer is checked against the
// spec's layout, not against our own reader).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "support/files.hpp"

namespace swarmbox::record::testing {

class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = swarmbox::testing::MakeTempDir("swarmbox-mcap-");
    ASSERT_FALSE(dir_.empty());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

inline std::uint64_t Le(std::string_view bytes, std::size_t at, int width) {
  std::uint64_t v = 0;
  for (int i = width - 1; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(i)]);
  return v;
}

struct TopRecord {
  std::uint8_t op;
  std::uint64_t offset;  // of the opcode
  std::string_view content;
};

// The records between the opening magic and the closing magic, in file order.
inline std::vector<TopRecord> TopLevelRecords(std::string_view file) {
  std::vector<TopRecord> out;
  std::size_t at = 8;
  while (at + 9 <= file.size() - 8) {
    const auto op = static_cast<std::uint8_t>(file[at]);
    const std::uint64_t length = Le(file, at + 1, 8);
    out.push_back({op, at, file.substr(at + 9, static_cast<std::size_t>(length))});
    at += 9 + static_cast<std::size_t>(length);
  }
  return out;
}

inline void WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace swarmbox::record::testing
