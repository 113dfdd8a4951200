// In-memory tar archives (libarchive): build contexts for POST /build and the bodies of the
// archive endpoints (PUT/GET /containers/{id}/archive). Pure: bytes in, bytes out, no files.
//
//   TarWriter tar;
//   tar.AddDirectory("tmp", 01777);
//   tar.AddFile("etc/passwd", "swarmbox:x:1000:1000::/tmp:/sbin/nologin\n", 0644);
//   Result<std::string> bytes = tar.Finish();
//   Result<std::vector<TarEntry>> entries = ReadTar(*bytes);
//
// Output is deterministic: entries in call order, mtime 0 unless given, owner as given (default
// 0:0), no user/group names, POSIX pax-restricted format (ustar, pax headers only when needed),
// so equal inputs give byte-equal archives (the image packer hashes them). Not thread-safe.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::docker {

struct TarEntry {
  enum class Type { kFile, kDirectory, kSymlink };
  Type type = Type::kFile;
  std::string path;     // relative, '/'-separated, no leading '/' (a leading '/' is dropped)
  std::string content;  // file bytes, or the symlink's target
  std::uint32_t mode = 0644;  // permission bits
  std::uint32_t uid = 0;
  std::uint32_t gid = 0;
  std::int64_t mtime_unix_s = 0;
  // Extended attributes written as pax SCHILY.xattr records, e.g. "security.capability" (file
  // capabilities, which Docker's builder keeps when it copies the file into a layer).
  std::map<std::string, std::string> xattrs;
};

// The three kinds of entry, owned by root with mtime 0 (what TarWriter::AddFile, AddDirectory and
// AddSymlink write).
TarEntry FileEntry(std::string_view path, std::string_view content, std::uint32_t mode = 0644);
TarEntry DirectoryEntry(std::string_view path, std::uint32_t mode = 0755);
TarEntry SymlinkEntry(std::string_view path, std::string_view target);  // mode 0777

class TarWriter {
 public:
  TarWriter();
  ~TarWriter();
  TarWriter(const TarWriter&) = delete;
  TarWriter& operator=(const TarWriter&) = delete;

  // Each Add returns the first libarchive error (kInternal) and the writer stays failed.
  Status Add(const TarEntry& entry);
  Status AddFile(std::string_view path, std::string_view content, std::uint32_t mode = 0644);
  Status AddDirectory(std::string_view path, std::uint32_t mode = 0755);
  Status AddSymlink(std::string_view path, std::string_view target);
  // Closes the archive and returns its bytes. The writer cannot be used afterwards.
  Result<std::string> Finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Reads every entry of an uncompressed (or compressed: libarchive detects it) tar. Hard links and
// other special entries are kProtocol errors naming the entry.
Result<std::vector<TarEntry>> ReadTar(std::string_view bytes);

}  // namespace swarmbox::docker
