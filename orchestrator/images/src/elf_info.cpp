#include "swarmbox/images/elf_info.hpp"

#include <cstring>
#include <optional>

namespace swarmbox::images {
namespace {

constexpr std::uint32_t kPtLoad = 1;
constexpr std::uint32_t kPtDynamic = 2;
constexpr std::uint32_t kPtInterp = 3;
constexpr std::int64_t kDtNull = 0;
constexpr std::int64_t kDtNeeded = 1;
constexpr std::int64_t kDtStrtab = 5;
constexpr std::int64_t kDtSoname = 14;
constexpr std::int64_t kDtRpath = 15;
constexpr std::int64_t kDtRunpath = 29;

// Bounds-checked reads in the file's byte order.
class Reader {
 public:
  Reader(std::string_view bytes, bool little) : bytes_(bytes), little_(little) {}
  std::optional<std::uint64_t> Read(std::uint64_t offset, std::size_t size) const {
    if (offset > bytes_.size() || size > bytes_.size() - offset) return std::nullopt;
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < size; ++i) {
      const auto byte = static_cast<unsigned char>(bytes_[static_cast<std::size_t>(offset) + i]);
      const std::size_t shift = little_ ? i : size - 1 - i;
      v |= static_cast<std::uint64_t>(byte) << (8 * shift);
    }
    return v;
  }
  std::optional<std::string> CString(std::uint64_t offset) const {
    if (offset >= bytes_.size()) return std::nullopt;
    const std::size_t start = static_cast<std::size_t>(offset);
    const std::size_t end = bytes_.find('\0', start);
    if (end == std::string_view::npos) return std::nullopt;
    return std::string(bytes_.substr(start, end - start));
  }

 private:
  std::string_view bytes_;
  bool little_;
};

struct Segment {
  std::uint32_t type = 0;
  std::uint64_t offset = 0;
  std::uint64_t vaddr = 0;
  std::uint64_t filesz = 0;
};

std::vector<std::string> SplitColon(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = text.find(':', start);
    std::string part = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (!part.empty()) out.push_back(std::move(part));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

}  // namespace

bool LooksLikeElf(std::string_view bytes) {
  return bytes.size() >= 4 && std::memcmp(bytes.data(), "\x7f" "ELF", 4) == 0;
}

namespace {

// The helpers below return why the file is unusable, or nullptr.
using Failure = const char*;

// e_type and e_machine into *info; the program header table's place.
struct ProgramHeaders {
  std::uint64_t offset = 0;
  std::uint64_t entry_size = 0;
  std::uint64_t count = 0;
};

Failure ReadFileHeader(const Reader& r, ElfInfo* info, ProgramHeaders* ph) {
  const std::size_t word = info->is_64 ? 8 : 4;
  const auto e_type = r.Read(16, 2);
  const auto e_machine = r.Read(18, 2);
  const auto e_phoff = r.Read(info->is_64 ? 32 : 28, word);
  const auto e_phentsize = r.Read(info->is_64 ? 54 : 42, 2);
  const auto e_phnum = r.Read(info->is_64 ? 56 : 44, 2);
  if (!e_type || !e_machine || !e_phoff || !e_phentsize || !e_phnum) return "truncated ELF header";
  info->kind = *e_type == 2   ? ElfInfo::Kind::kExecutable
               : *e_type == 3 ? ElfInfo::Kind::kSharedObject
                              : ElfInfo::Kind::kOther;
  info->machine = static_cast<std::uint16_t>(*e_machine);
  *ph = {*e_phoff, *e_phentsize, *e_phnum};
  return nullptr;
}

Failure ReadSegments(const Reader& r, bool is_64, const ProgramHeaders& table, std::vector<Segment>* segments) {
  for (std::uint64_t i = 0; i < table.count; ++i) {
    const std::uint64_t ph = table.offset + i * table.entry_size;
    Segment s;
    const auto type = r.Read(ph, 4);
    std::optional<std::uint64_t> offset, vaddr, filesz;
    if (is_64) {
      offset = r.Read(ph + 8, 8);
      vaddr = r.Read(ph + 16, 8);
      filesz = r.Read(ph + 32, 8);
    } else {
      offset = r.Read(ph + 4, 4);
      vaddr = r.Read(ph + 8, 4);
      filesz = r.Read(ph + 16, 4);
    }
    if (!type || !offset || !vaddr || !filesz) return "program header table out of bounds";
    s.type = static_cast<std::uint32_t>(*type);
    s.offset = *offset;
    s.vaddr = *vaddr;
    s.filesz = *filesz;
    segments->push_back(s);
  }
  return nullptr;
}

std::optional<std::uint64_t> VaddrToOffset(const std::vector<Segment>& segments, std::uint64_t vaddr) {
  for (const Segment& s : segments) {
    if (s.type == kPtLoad && vaddr >= s.vaddr && vaddr < s.vaddr + s.filesz) {
      return s.offset + (vaddr - s.vaddr);
    }
  }
  return std::nullopt;
}

Failure ReadInterpreter(const Reader& r, const std::vector<Segment>& segments, ElfInfo* info) {
  for (const Segment& s : segments) {
    if (s.type == kPtInterp) {
      auto interp = r.CString(s.offset);
      if (!interp) return "PT_INTERP out of bounds";
      info->interpreter = *interp;
    }
  }
  return nullptr;
}

// One PT_DYNAMIC segment: DT_NEEDED, DT_RUNPATH, DT_RPATH and DT_SONAME into *info.
Failure ReadDynamicSegment(const Reader& r, const Segment& s, const std::vector<Segment>& segments, ElfInfo* info) {
  const std::size_t word = info->is_64 ? 8 : 4;
  info->dynamic = true;
  const std::size_t entry = 2 * word;
  std::vector<std::pair<std::int64_t, std::uint64_t>> dyn;
  std::optional<std::uint64_t> strtab;
  for (std::uint64_t off = s.offset; off + entry <= s.offset + s.filesz; off += entry) {
    const auto tag = r.Read(off, word);
    const auto val = r.Read(off + word, word);
    if (!tag || !val) return "dynamic section out of bounds";
    const auto t = static_cast<std::int64_t>(*tag);
    if (t == kDtNull) break;
    if (t == kDtStrtab) strtab = VaddrToOffset(segments, *val);
    dyn.emplace_back(t, *val);
  }
  if (!strtab) return dyn.empty() ? nullptr : "dynamic section without a string table";
  for (const auto& [tag, val] : dyn) {
    if (tag != kDtNeeded && tag != kDtRunpath && tag != kDtRpath && tag != kDtSoname) continue;
    auto text = r.CString(*strtab + val);
    if (!text) return "dynamic string out of bounds";
    if (tag == kDtNeeded) info->needed.push_back(*text);
    if (tag == kDtRunpath) info->runpath = SplitColon(*text);
    if (tag == kDtRpath) info->rpath = SplitColon(*text);
    if (tag == kDtSoname) info->soname = *text;
  }
  return nullptr;
}

// The ELF file's header, program headers, interpreter and dynamic section into *info.
Failure ReadElf(std::string_view bytes, ElfInfo* info) {
  if (!LooksLikeElf(bytes)) return "no ELF magic";
  if (bytes.size() < 52) return "truncated ELF header";
  const auto cls = static_cast<unsigned char>(bytes[4]);
  const auto data = static_cast<unsigned char>(bytes[5]);
  if ((cls != 1 && cls != 2) || (data != 1 && data != 2)) return "unknown ELF class or data";
  info->is_64 = cls == 2;
  const Reader r(bytes, data == 1);
  ProgramHeaders table;
  if (Failure f = ReadFileHeader(r, info, &table)) return f;
  std::vector<Segment> segments;
  if (Failure f = ReadSegments(r, info->is_64, table, &segments)) return f;
  if (Failure f = ReadInterpreter(r, segments, info)) return f;
  for (const Segment& s : segments) {
    if (s.type != kPtDynamic) continue;
    if (Failure f = ReadDynamicSegment(r, s, segments, info)) return f;
  }
  return nullptr;
}

}  // namespace

Result<ElfInfo> ReadElfInfo(std::string_view bytes, std::string_view what) {
  ElfInfo info;
  if (Failure why = ReadElf(bytes, &info)) {
    return Error(ErrorCode::kInvalidArgument, "not a usable ELF file: " + std::string(why), std::string(what));
  }
  return info;
}

}  // namespace swarmbox::images
