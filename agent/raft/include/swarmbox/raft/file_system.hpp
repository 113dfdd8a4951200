// FileSystem: the file operations the write-ahead log needs, behind an interface so that tests
// can inject write and fsync failures (STYLE.md 3). PosixFileSystem is the real one.
// Errors are kIo with the path in `where` and strerror(errno) in the message; a missing file is
// kNotFound.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/types.hpp"

namespace swarmbox::raft {

class AppendFile {
 public:
  virtual ~AppendFile() = default;
  virtual Status Append(std::span<const std::uint8_t> bytes) = 0;  // all bytes, or an error
  virtual Status Sync() = 0;                                        // fsync
};

class FileSystem {
 public:
  virtual ~FileSystem() = default;
  virtual Status CreateDirs(const std::string& path) = 0;
  virtual Result<Bytes> ReadFile(const std::string& path) = 0;
  // Opens for appending, creating the file when missing.
  virtual Result<std::unique_ptr<AppendFile>> OpenAppend(const std::string& path) = 0;
  // Replaces `path` atomically and durably: write path.tmp, fsync, rename, fsync the directory.
  virtual Status WriteFileAtomic(const std::string& path, std::span<const std::uint8_t> bytes) = 0;
  virtual Status Truncate(const std::string& path, std::uint64_t size) = 0;
};

class PosixFileSystem final : public FileSystem {
 public:
  Status CreateDirs(const std::string& path) override;
  Result<Bytes> ReadFile(const std::string& path) override;
  Result<std::unique_ptr<AppendFile>> OpenAppend(const std::string& path) override;
  Status WriteFileAtomic(const std::string& path, std::span<const std::uint8_t> bytes) override;
  Status Truncate(const std::string& path, std::uint64_t size) override;
};

}  // namespace swarmbox::raft
