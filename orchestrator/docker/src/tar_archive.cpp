#include "swarmbox/docker/tar_archive.hpp"

#include <archive.h>
#include <archive_entry.h>

#include <memory>
#include <utility>

namespace swarmbox::docker {

struct TarWriter::Impl {
  archive* a = nullptr;
  std::string out;
  bool failed = false;
  bool finished = false;
};

namespace {

la_ssize_t AppendToString(archive* /*a*/, void* user, const void* buffer, size_t length) {
  static_cast<std::string*>(user)->append(static_cast<const char*>(buffer), length);
  return static_cast<la_ssize_t>(length);
}

// Relative, no leading or trailing '/' (libarchive writes directories as "dir/").
std::string Normalize(std::string_view path) {
  while (!path.empty() && path.front() == '/') path.remove_prefix(1);
  while (!path.empty() && path.back() == '/') path.remove_suffix(1);
  return std::string(path);
}

Error ArchiveError(archive* a, std::string_view doing) {
  const char* text = archive_error_string(a);
  return Error(ErrorCode::kInternal,
               std::string(doing) + ": " + (text != nullptr ? text : "unknown libarchive error"),
               "libarchive");
}

// Symlinks carry no permissions of their own; tar writes them as rwxrwxrwx.
constexpr std::uint32_t kSymlinkMode = 0777;

// The libarchive header for `entry` (path already normalized); the caller frees it.
archive_entry* NewArchiveEntry(const TarEntry& entry, const std::string& path) {
  archive_entry* e = archive_entry_new();
  archive_entry_set_pathname(e, path.c_str());
  archive_entry_set_uid(e, entry.uid);
  archive_entry_set_gid(e, entry.gid);
  archive_entry_set_mtime(e, entry.mtime_unix_s, 0);
  for (const auto& [name, value] : entry.xattrs) {
    archive_entry_xattr_add_entry(e, name.c_str(), value.data(), value.size());
  }
  switch (entry.type) {
    case TarEntry::Type::kFile:
      archive_entry_set_filetype(e, AE_IFREG);
      archive_entry_set_perm(e, entry.mode);
      archive_entry_set_size(e, static_cast<la_int64_t>(entry.content.size()));
      break;
    case TarEntry::Type::kDirectory:
      archive_entry_set_filetype(e, AE_IFDIR);
      archive_entry_set_perm(e, entry.mode);
      archive_entry_set_size(e, 0);
      break;
    case TarEntry::Type::kSymlink:
      archive_entry_set_filetype(e, AE_IFLNK);
      archive_entry_set_perm(e, kSymlinkMode);
      archive_entry_set_symlink(e, entry.content.c_str());
      archive_entry_set_size(e, 0);
      break;
  }
  return e;
}

// Writes the header, then a file's bytes; the first libarchive failure names the entry.
Status WriteArchiveEntry(archive* a, archive_entry* header, const TarEntry& entry, const std::string& path) {
  if (archive_write_header(a, header) != ARCHIVE_OK) {
    return ArchiveError(a, "writing tar header for " + path);
  }
  if (entry.type == TarEntry::Type::kFile && !entry.content.empty()) {
    const la_ssize_t n = archive_write_data(a, entry.content.data(), entry.content.size());
    if (n < 0 || static_cast<std::size_t>(n) != entry.content.size()) {
      return ArchiveError(a, "writing tar data for " + path);
    }
  }
  return Ok{};
}

}  // namespace

TarWriter::TarWriter() : impl_(std::make_unique<Impl>()) {
  impl_->a = archive_write_new();
  SWARMBOX_CHECK(impl_->a != nullptr);
  archive_write_set_format_pax_restricted(impl_->a);
  archive_write_set_bytes_in_last_block(impl_->a, 1);
  if (archive_write_open(impl_->a, &impl_->out, nullptr, &AppendToString, nullptr) != ARCHIVE_OK) {
    impl_->failed = true;
  }
}

TarWriter::~TarWriter() {
  if (impl_->a != nullptr) archive_write_free(impl_->a);
}

Status TarWriter::Add(const TarEntry& entry) {
  if (impl_->finished) return Error(ErrorCode::kInternal, "tar already finished", "libarchive");
  if (impl_->failed) return ArchiveError(impl_->a, "tar writer failed earlier");
  const std::string path = Normalize(entry.path);
  if (path.empty()) return Error(ErrorCode::kInvalidArgument, "tar entry with an empty path");
  archive_entry* header = NewArchiveEntry(entry, path);
  Status status = WriteArchiveEntry(impl_->a, header, entry, path);
  archive_entry_free(header);
  if (!status) impl_->failed = true;
  return status;
}

namespace {

// Every kind of entry is one constructor: root-owned, mtime 0, the given type, path, content, mode.
TarEntry MakeEntry(TarEntry::Type type, std::string_view path, std::string_view content, std::uint32_t mode) {
  TarEntry entry;
  entry.type = type;
  entry.path = std::string(path);
  entry.content = std::string(content);
  entry.mode = mode;
  return entry;
}

}  // namespace

TarEntry FileEntry(std::string_view path, std::string_view content, std::uint32_t mode) {
  return MakeEntry(TarEntry::Type::kFile, path, content, mode);
}

TarEntry DirectoryEntry(std::string_view path, std::uint32_t mode) {
  return MakeEntry(TarEntry::Type::kDirectory, path, "", mode);
}

TarEntry SymlinkEntry(std::string_view path, std::string_view target) {
  return MakeEntry(TarEntry::Type::kSymlink, path, target, kSymlinkMode);
}

Status TarWriter::AddFile(std::string_view path, std::string_view content, std::uint32_t mode) {
  return Add(FileEntry(path, content, mode));
}

Status TarWriter::AddDirectory(std::string_view path, std::uint32_t mode) { return Add(DirectoryEntry(path, mode)); }

Status TarWriter::AddSymlink(std::string_view path, std::string_view target) { return Add(SymlinkEntry(path, target)); }

Result<std::string> TarWriter::Finish() {
  if (impl_->finished) return Error(ErrorCode::kInternal, "tar already finished", "libarchive");
  impl_->finished = true;
  if (impl_->failed) return ArchiveError(impl_->a, "tar writer failed earlier");
  if (archive_write_close(impl_->a) != ARCHIVE_OK) return ArchiveError(impl_->a, "closing tar");
  return std::move(impl_->out);
}

namespace {

struct ArchiveReadFree {
  void operator()(archive* a) const { archive_read_free(a); }
};
using ArchiveReader = std::unique_ptr<archive, ArchiveReadFree>;

// Read errors are the peer's bytes being wrong, so kProtocol (the writer's are kInternal).
Error ReadError(archive* a, std::string_view doing) {
  Error e = ArchiveError(a, doing);
  return Error(ErrorCode::kProtocol, e.message(), e.where());
}

// Path, permissions, owner, mtime and extended attributes of the entry `e` describes.
TarEntry ReadEntryMetadata(archive_entry* e) {
  TarEntry entry;
  entry.path = Normalize(archive_entry_pathname(e) != nullptr ? archive_entry_pathname(e) : "");
  entry.mode = static_cast<std::uint32_t>(archive_entry_perm(e));
  entry.uid = static_cast<std::uint32_t>(archive_entry_uid(e));
  entry.gid = static_cast<std::uint32_t>(archive_entry_gid(e));
  entry.mtime_unix_s = archive_entry_mtime(e);
  if (archive_entry_xattr_reset(e) > 0) {
    const char* name = nullptr;
    const void* value = nullptr;
    size_t size = 0;
    while (archive_entry_xattr_next(e, &name, &value, &size) == ARCHIVE_OK) {
      entry.xattrs[name] = std::string(static_cast<const char*>(value), size);
    }
  }
  return entry;
}

// Appends the current entry's data to entry.content.
Status ReadFileContent(archive* a, TarEntry& entry) {
  char buffer[64 * 1024];
  while (true) {
    const la_ssize_t n = archive_read_data(a, buffer, sizeof(buffer));
    if (n < 0) return ReadError(a, "reading tar data of " + entry.path);
    if (n == 0) return Ok{};
    entry.content.append(buffer, static_cast<std::size_t>(n));
  }
}

// Sets the entry's type (and content: a file's bytes, a symlink's target) from its header.
Status ReadEntryBody(archive* a, archive_entry* e, TarEntry& entry) {
  const auto type = archive_entry_filetype(e);
  if (type == AE_IFREG && archive_entry_hardlink(e) == nullptr) {
    entry.type = TarEntry::Type::kFile;
    return ReadFileContent(a, entry);
  }
  if (type == AE_IFDIR) {
    entry.type = TarEntry::Type::kDirectory;
    return Ok{};
  }
  if (type == AE_IFLNK) {
    entry.type = TarEntry::Type::kSymlink;
    const char* target = archive_entry_symlink(e);
    entry.content = target != nullptr ? target : "";
    return Ok{};
  }
  return Error(ErrorCode::kProtocol,
               "unsupported tar entry type for " + entry.path + " (hard link or special file)", "libarchive");
}

}  // namespace

Result<std::vector<TarEntry>> ReadTar(std::string_view bytes) {
  ArchiveReader reader(archive_read_new());
  archive* a = reader.get();
  SWARMBOX_CHECK(a != nullptr);
  archive_read_support_format_tar(a);
  archive_read_support_filter_all(a);
  std::vector<TarEntry> entries;
  if (archive_read_open_memory(a, bytes.data(), bytes.size()) != ARCHIVE_OK) {
    return ReadError(a, "opening tar");
  }
  archive_entry* e = nullptr;
  while (true) {
    const int rc = archive_read_next_header(a, &e);
    if (rc == ARCHIVE_EOF) break;
    if (rc != ARCHIVE_OK && rc != ARCHIVE_WARN) return ReadError(a, "reading tar header");
    TarEntry entry = ReadEntryMetadata(e);
    if (Status body = ReadEntryBody(a, e, entry); !body) return body.error();
    entries.push_back(std::move(entry));
  }
  return entries;
}

}  // namespace swarmbox::docker
