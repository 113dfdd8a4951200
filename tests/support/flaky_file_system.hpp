// FlakyFileSystem: the real (POSIX) file system of the Raft storage, whose appended files fail
// Sync() once `fail_sync` is set, with "fsync: Input/output error (injected)" (kIo). For the
// tests of the loud stop when a WAL cannot be made durable. Header-only: link swarmbox::raft.
//
//   FlakyFileSystem fs;  config.file_system = &fs;  ...  fs.fail_sync = true;
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "swarmbox/raft/file_system.hpp"

namespace swarmbox::testing {

class FlakyFileSystem final : public raft::FileSystem {
 public:
  std::atomic<bool> fail_sync{false};  // may be set from another thread than the one writing

  Status CreateDirs(const std::string& p) override { return real_.CreateDirs(p); }
  Result<raft::Bytes> ReadFile(const std::string& p) override { return real_.ReadFile(p); }
  Result<std::unique_ptr<raft::AppendFile>> OpenAppend(const std::string& p) override {
    auto f = real_.OpenAppend(p);
    if (!f) return std::move(f).error();
    return std::unique_ptr<raft::AppendFile>(new File(std::move(*f), &fail_sync));
  }
  Status WriteFileAtomic(const std::string& p, std::span<const std::uint8_t> b) override {
    return real_.WriteFileAtomic(p, b);
  }
  Status Truncate(const std::string& p, std::uint64_t size) override { return real_.Truncate(p, size); }

 private:
  class File final : public raft::AppendFile {
   public:
    File(std::unique_ptr<raft::AppendFile> f, const std::atomic<bool>* fail)
        : f_(std::move(f)), fail_(fail) {}
    Status Append(std::span<const std::uint8_t> b) override { return f_->Append(b); }
    Status Sync() override {
      if (fail_->load()) return Error(ErrorCode::kIo, "fsync: Input/output error (injected)");
      return f_->Sync();
    }

   private:
    std::unique_ptr<raft::AppendFile> f_;
    const std::atomic<bool>* fail_;
  };
  raft::PosixFileSystem real_;
};

}  // namespace swarmbox::testing
