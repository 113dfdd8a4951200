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

Result<ElfInfo> ReadElfInfo(std::string_view bytes, std::string_view what) {
  auto bad = [&](std::string_view why) {
    return Error(ErrorCode::kInvalidArgument, "not a usable ELF file: " + std::string(why),
                 std::string(what));
  };
  if (!LooksLikeElf(bytes)) return bad("no ELF magic");
  if (bytes.size() < 52) return bad("truncated ELF header");
  const auto cls = static_cast<unsigned char>(bytes[4]);
  const auto data = static_cast<unsigned char>(bytes[5]);
  if ((cls != 1 && cls != 2) || (data != 1 && data != 2)) return bad("unknown ELF class or data");
  ElfInfo info;
  info.is_64 = cls == 2;
  const Reader r(bytes, data == 1);
  const std::size_t word = info.is_64 ? 8 : 4;

  const auto e_type = r.Read(16, 2);
  const auto e_machine = r.Read(18, 2);
  const auto e_phoff = r.Read(info.is_64 ? 32 : 28, word);
  const auto e_phentsize = r.Read(info.is_64 ? 54 : 42, 2);
  const auto e_phnum = r.Read(info.is_64 ? 56 : 44, 2);
  if (!e_type || !e_machine || !e_phoff || !e_phentsize || !e_phnum) {
    return bad("truncated ELF header");
  }
  info.kind = *e_type == 2   ? ElfInfo::Kind::kExecutable
              : *e_type == 3 ? ElfInfo::Kind::kSharedObject
                             : ElfInfo::Kind::kOther;
  info.machine = static_cast<std::uint16_t>(*e_machine);

  std::vector<Segment> segments;
  for (std::uint64_t i = 0; i < *e_phnum; ++i) {
    const std::uint64_t ph = *e_phoff + i * *e_phentsize;
    Segment s;
    const auto type = r.Read(ph, 4);
    std::optional<std::uint64_t> offset, vaddr, filesz;
    if (info.is_64) {
      offset = r.Read(ph + 8, 8);
      vaddr = r.Read(ph + 16, 8);
      filesz = r.Read(ph + 32, 8);
    } else {
      offset = r.Read(ph + 4, 4);
      vaddr = r.Read(ph + 8, 4);
      filesz = r.Read(ph + 16, 4);
    }
    if (!type || !offset || !vaddr || !filesz) return bad("program header table out of bounds");
    s.type = static_cast<std::uint32_t>(*type);
    s.offset = *offset;
    s.vaddr = *vaddr;
    s.filesz = *filesz;
    segments.push_back(s);
  }

  auto vaddr_to_offset = [&](std::uint64_t vaddr) -> std::optional<std::uint64_t> {
    for (const Segment& s : segments) {
      if (s.type == kPtLoad && vaddr >= s.vaddr && vaddr < s.vaddr + s.filesz) {
        return s.offset + (vaddr - s.vaddr);
      }
    }
    return std::nullopt;
  };

  for (const Segment& s : segments) {
    if (s.type == kPtInterp) {
      auto interp = r.CString(s.offset);
      if (!interp) return bad("PT_INTERP out of bounds");
      info.interpreter = *interp;
    }
  }
  for (const Segment& s : segments) {
    if (s.type != kPtDynamic) continue;
    info.dynamic = true;
    const std::size_t entry = 2 * word;
    std::vector<std::pair<std::int64_t, std::uint64_t>> dyn;
    std::optional<std::uint64_t> strtab;
    for (std::uint64_t off = s.offset; off + entry <= s.offset + s.filesz; off += entry) {
      const auto tag = r.Read(off, word);
      const auto val = r.Read(off + word, word);
      if (!tag || !val) return bad("dynamic section out of bounds");
      const auto t = static_cast<std::int64_t>(*tag);
      if (t == kDtNull) break;
      if (t == kDtStrtab) strtab = vaddr_to_offset(*val);
      dyn.emplace_back(t, *val);
    }
    if (!strtab) {
      if (dyn.empty()) continue;
      return bad("dynamic section without a string table");
    }
    for (const auto& [tag, val] : dyn) {
      if (tag != kDtNeeded && tag != kDtRunpath && tag != kDtRpath && tag != kDtSoname) continue;
      auto text = r.CString(*strtab + val);
      if (!text) return bad("dynamic string out of bounds");
      if (tag == kDtNeeded) info.needed.push_back(*text);
      if (tag == kDtRunpath) info.runpath = SplitColon(*text);
      if (tag == kDtRpath) info.rpath = SplitColon(*text);
      if (tag == kDtSoname) info.soname = *text;
    }
  }
  return info;
}

}  // namespace swarmbox::images
