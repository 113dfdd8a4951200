#include "swarmbox/images/tag_cache.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "swarmbox/images/content_hash.hpp"
#include "swarmbox/images/library_closure.hpp"

namespace swarmbox::images {

namespace fs = std::filesystem;

namespace {

// Length-prefixed fields: no separator can be confused with content.
void Field(std::string& out, std::string_view name, std::string_view value) {
  out += name;
  out += ' ';
  out += std::to_string(value.size());
  out += ':';
  out += value;
  out += '\n';
}

}  // namespace

std::string SpecKey(const ImageSpec& spec) {
  std::string d;
  Field(d, "repository", spec.repository);
  Field(d, "component", spec.component);
  for (const auto* group : {&spec.executables, &spec.plugins, &spec.files}) {
    Field(d, "group", std::to_string(group == &spec.executables ? 0 : group == &spec.plugins ? 1 : 2));
    for (const HostFile& f : *group) {
      Field(d, "host", f.host_path);
      Field(d, "image", f.image_path);
      Field(d, "mode", std::to_string(f.mode));
    }
  }
  for (const auto& [path, content] : spec.inline_files) {
    Field(d, "inline", path);
    Field(d, "content", content);
  }
  for (const auto& [path, target] : spec.symlinks) {
    Field(d, "symlink", path);
    Field(d, "target", target);
  }
  for (const auto& [path, mode] : spec.directories) {
    Field(d, "directory", path);
    Field(d, "mode", std::to_string(mode));
  }
  for (const std::string& e : spec.entrypoint) Field(d, "entrypoint", e);
  for (const std::string& c : spec.cmd) Field(d, "cmd", c);
  for (const auto& [k, v] : spec.env) {
    Field(d, "env", k);
    Field(d, "value", v);
  }
  Field(d, "user", spec.user);
  Field(d, "workdir", spec.workdir);
  for (const auto& [k, v] : spec.labels) {
    Field(d, "label", k);
    Field(d, "value", v);
  }
  Field(d, "strip_debug", spec.strip_debug ? "1" : "0");
  Field(d, "tag_digits", std::to_string(kTagHashDigits));
  return Sha256Hex(d);
}

std::string FormatTagCacheEntry(const TagCacheEntry& entry) {
  std::ostringstream out;
  out << "tag " << entry.tag << '\n';
  for (const FileStamp& f : entry.files) {
    out << "file " << f.size_bytes << ' ' << f.mtime_ns << ' ' << f.inode << ' ' << f.path << '\n';
  }
  return out.str();
}

Result<TagCacheEntry> ParseTagCacheEntry(const std::string& text) {
  TagCacheEntry entry;
  std::istringstream in(text);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    std::istringstream fields(line);
    std::string kind;
    fields >> kind;
    if (n == 1) {
      if (kind != "tag" || !(fields >> entry.tag) || entry.tag.find(':') == std::string::npos) {
        return Error(ErrorCode::kProtocol, "tag cache entry: line 1 is not 'tag <repository:hash>'");
      }
      continue;
    }
    FileStamp f;
    if (kind != "file" || !(fields >> f.size_bytes >> f.mtime_ns >> f.inode) || fields.get() != ' ') {
      return Error(ErrorCode::kProtocol, "tag cache entry: line " + std::to_string(n) +
                                             " is not 'file <size> <mtime_ns> <inode> <path>'");
    }
    std::getline(fields, f.path);
    if (f.path.empty()) {
      return Error(ErrorCode::kProtocol, "tag cache entry: line " + std::to_string(n) + " has no path");
    }
    entry.files.push_back(std::move(f));
  }
  if (entry.tag.empty()) return Error(ErrorCode::kProtocol, "tag cache entry: empty");
  return entry;
}

Result<FileStamp> StampFile(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return Error(ErrorCode::kNotFound, "cannot stat", path);
  FileStamp f;
  f.path = path;
  f.size_bytes = static_cast<std::int64_t>(st.st_size);
  f.mtime_ns = static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec;
  f.inode = static_cast<std::uint64_t>(st.st_ino);
  return f;
}

std::string DefaultTagCacheDir() {
  auto env = [](const char* name) -> std::string {
    const char* v = std::getenv(name);
    return v == nullptr ? std::string() : std::string(v);
  };
  if (std::string d = env("SWARMBOX_CACHE_DIR"); !d.empty()) return (fs::path(d) / "image-tags").string();
  if (std::string d = env("XDG_CACHE_HOME"); !d.empty()) {
    return (fs::path(d) / "swarmbox" / "image-tags").string();
  }
  if (std::string d = env("HOME"); !d.empty()) {
    return (fs::path(d) / ".cache" / "swarmbox" / "image-tags").string();
  }
  return {};
}

std::optional<std::string> TagCache::Lookup(const ImageSpec& spec) const {
  if (dir_.empty()) return std::nullopt;
  auto text = ReadFileBytes((fs::path(dir_) / (SpecKey(spec) + ".tag")).string());
  if (!text) return std::nullopt;
  auto entry = ParseTagCacheEntry(*text);
  if (!entry || entry->files.empty()) return std::nullopt;
  for (const FileStamp& f : entry->files) {
    auto now = StampFile(f.path);
    if (!now || !(*now == f)) return std::nullopt;
  }
  return entry->tag;
}

Status TagCache::Remember(const ImageSpec& spec, const PackedContext& ctx) const {
  if (dir_.empty()) return Ok{};
  TagCacheEntry entry;
  entry.tag = ctx.tag;
  std::vector<std::string> paths = ctx.host_files;
  if (!spec.executables.empty() || !spec.plugins.empty()) paths.push_back("/etc/ld.so.cache");
  for (const std::string& p : paths) {
    auto stamp = StampFile(p);
    if (!stamp) {
      if (p == "/etc/ld.so.cache") continue;  // a system without one
      return stamp.error().Context("remembering the tag of " + spec.repository);
    }
    entry.files.push_back(std::move(*stamp));
  }
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) return Error(ErrorCode::kIo, "cannot create the tag cache: " + ec.message(), dir_);
  const fs::path final_path = fs::path(dir_) / (SpecKey(spec) + ".tag");
  std::random_device rd;
  const fs::path tmp = fs::path(dir_) / (".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << FormatTagCacheEntry(entry);
    if (!out) return Error(ErrorCode::kIo, "cannot write the tag cache", tmp.string());
  }
  fs::rename(tmp, final_path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return Error(ErrorCode::kIo, "cannot write the tag cache", final_path.string());
  }
  return Ok{};
}

}  // namespace swarmbox::images
