// TagCache: the tag an ImageSpec packs to, remembered between runs, so that `swarmbox run` does
// not read, strip and hash ~100 MB of binaries and libraries again (PackContext: 1-2.5 s) when
// nothing changed.
//
//   TagCache cache(DefaultTagCacheDir());        // ~/.cache/swarmbox/image-tags
//   if (auto tag = cache.Lookup(spec)) ...       // a tag, when every input file is as it was
//   ... PackContext(spec) ...
//   cache.Remember(spec, ctx);                   // after packing
//
// One file per spec (named by SpecKey: a hash of every field of the spec, file contents aside)
// holding the tag and a stamp (size, mtime in ns, inode) of every host file that went into the
// context: the spec's files, their shared-library closure, and /etc/ld.so.cache (so a library
// that appears elsewhere on the search path is noticed). An entry is used only while every stamp
// still matches; anything unreadable is a miss. Writes go to a temporary file renamed into place,
// so parallel runs never read half an entry. Thread-safe (no shared state besides the files).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/images/image_context.hpp"
#include "swarmbox/images/image_spec.hpp"

namespace swarmbox::images {

struct FileStamp {
  std::string path;
  std::int64_t size_bytes = 0;
  std::int64_t mtime_ns = 0;
  std::uint64_t inode = 0;
  bool operator==(const FileStamp& o) const {
    return path == o.path && size_bytes == o.size_bytes && mtime_ns == o.mtime_ns &&
           inode == o.inode;
  }
};

struct TagCacheEntry {
  std::string tag;
  std::vector<FileStamp> files;
};

// Pure: a SHA-256 over every field of the spec (paths, modes, inline files, entrypoint...), hex.
std::string SpecKey(const ImageSpec& spec);
// Pure: the entry as text ("tag <tag>\n" then "file <size> <mtime_ns> <inode> <path>\n" lines)
// and back; kProtocol on anything else.
std::string FormatTagCacheEntry(const TagCacheEntry& entry);
Result<TagCacheEntry> ParseTagCacheEntry(const std::string& text);
// The stamp of a file now (symlinks followed); kNotFound when it cannot be stat'ed.
Result<FileStamp> StampFile(const std::string& path);

// $SWARMBOX_CACHE_DIR/image-tags, else $XDG_CACHE_HOME/swarmbox/image-tags, else
// $HOME/.cache/swarmbox/image-tags; "" when none of them is set (no caching).
std::string DefaultTagCacheDir();

class TagCache {
 public:
  explicit TagCache(std::string dir) : dir_(std::move(dir)) {}
  const std::string& dir() const { return dir_; }
  // The remembered tag of `spec` when its entry exists and every file stamp still matches.
  std::optional<std::string> Lookup(const ImageSpec& spec) const;
  // Stamps ctx.host_files and writes the entry (creating the folder). A failure only means the
  // next run packs again: it is returned for logging, never fatal.
  Status Remember(const ImageSpec& spec, const PackedContext& ctx) const;

 private:
  std::string dir_;
};

}  // namespace swarmbox::images
