#include "swarmbox/dsl/user_software.hpp"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>

namespace swarmbox::dsl {

namespace {

using yaml::Node;

Node Str(std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); }
Node Plain(std::string s) { return Node::Scalar(std::move(s)); }

Node StringList(const std::vector<std::string>& items) {
  Node list = Node::Sequence();
  for (const std::string& s : items) list.Append(Str(s));
  return list;
}

Node ListNode(std::vector<std::string> args) {
  if (args.empty()) return Node::Null();
  return StringList(args);
}

// Little/big-endian unsigned read of `size` bytes at `offset`; nullopt past the end.
std::optional<std::uint64_t> ReadUnsigned(std::string_view bytes, std::uint64_t offset, std::size_t size,
                                          bool little) {
  if (offset > bytes.size() || bytes.size() - offset < size) return std::nullopt;
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < size; ++i) {
    const auto b = static_cast<unsigned char>(bytes[offset + (little ? size - 1 - i : i)]);
    v = (v << 8) | b;
  }
  return v;
}

}  // namespace

std::string_view BrainKindName(BrainKind kind) {
  switch (kind) {
    case BrainKind::kBuiltin: return "builtin";
    case BrainKind::kLibrary: return "library";
    case BrainKind::kProgram: return "program";
    case BrainKind::kDockerfile: return "dockerfile";
    case BrainKind::kImage: return "image";
  }
  return "builtin";
}

std::string_view ComponentSourceName(ComponentSource source) {
  switch (source) {
    case ComponentSource::kImage: return "image";
    case ComponentSource::kProgram: return "program";
    case ComponentSource::kDockerfile: return "dockerfile";
  }
  return "image";
}

std::string BrainSpec::ArgsJson() const {
  if (args.is_null() || !args.is_mapping()) return "{}";
  return yaml::EmitJson(args);
}

std::vector<std::string> BrainSpec::ArgList() const {
  std::vector<std::string> out;
  if (!args.is_sequence()) return out;
  for (const Node& item : args.items()) out.push_back(item.scalar());
  return out;
}

BrainSpec BrainSpec::Library(std::string path, std::string name, yaml::Node args) {
  BrainSpec b;
  b.kind = BrainKind::kLibrary;
  b.path = std::move(path);
  b.name = std::move(name);
  b.args = std::move(args);
  return b;
}
BrainSpec BrainSpec::Program(std::string path, std::vector<std::string> args) {
  BrainSpec b;
  b.kind = BrainKind::kProgram;
  b.path = std::move(path);
  b.args = ListNode(std::move(args));
  return b;
}
BrainSpec BrainSpec::Dockerfile(std::string path, std::vector<std::string> args) {
  BrainSpec b = Program(std::move(path), std::move(args));
  b.kind = BrainKind::kDockerfile;
  return b;
}
BrainSpec BrainSpec::Image(std::string reference, std::vector<std::string> args) {
  BrainSpec b = Program(std::move(reference), std::move(args));
  b.kind = BrainKind::kImage;
  return b;
}

UserComponentSpec UserComponentSpec::Image(std::string name, std::string reference) {
  UserComponentSpec c;
  c.name = std::move(name);
  c.source = ComponentSource::kImage;
  c.ref = std::move(reference);
  return c;
}
UserComponentSpec UserComponentSpec::Program(std::string name, std::string path) {
  UserComponentSpec c = Image(std::move(name), std::move(path));
  c.source = ComponentSource::kProgram;
  return c;
}
UserComponentSpec UserComponentSpec::Dockerfile(std::string name, std::string path) {
  UserComponentSpec c = Image(std::move(name), std::move(path));
  c.source = ComponentSource::kDockerfile;
  return c;
}

std::string_view FileKindName(FileKind kind) {
  switch (kind) {
    case FileKind::kMissing: return "no such file";
    case FileKind::kOther: return "not an ELF file";
    case FileKind::kElfExecutable: return "an ELF executable";
    case FileKind::kElfShared: return "an ELF shared object";
    case FileKind::kElfOther: return "an ELF file that is neither a program nor a shared object";
    case FileKind::kDirectory: return "a directory";
  }
  return "not an ELF file";
}

FileKind ClassifyFileBytes(std::string_view head) {
  if (head.size() < 4 || std::memcmp(head.data(), "\x7f" "ELF", 4) != 0) return FileKind::kOther;
  if (head.size() < 52) return FileKind::kElfOther;
  const auto cls = static_cast<unsigned char>(head[4]);
  const auto data = static_cast<unsigned char>(head[5]);
  if ((cls != 1 && cls != 2) || (data != 1 && data != 2)) return FileKind::kElfOther;
  const bool is64 = cls == 2;
  const bool little = data == 1;
  const std::size_t word = is64 ? 8 : 4;
  const auto type = ReadUnsigned(head, 16, 2, little);
  const auto phoff = ReadUnsigned(head, is64 ? 32 : 28, word, little);
  const auto phentsize = ReadUnsigned(head, is64 ? 54 : 42, 2, little);
  const auto phnum = ReadUnsigned(head, is64 ? 56 : 44, 2, little);
  if (!type || !phoff || !phentsize || !phnum) return FileKind::kElfOther;
  if (*type == 2) return FileKind::kElfExecutable;  // ET_EXEC
  if (*type != 3) return FileKind::kElfOther;       // not ET_DYN
  // ET_DYN: a PIE program has an interpreter (PT_INTERP = 3), a shared object none.
  for (std::uint64_t i = 0; i < *phnum; ++i) {
    const auto p_type = ReadUnsigned(head, *phoff + i * *phentsize, 4, little);
    if (!p_type) return FileKind::kElfOther;  // program headers beyond what was read
    if (*p_type == 3) return FileKind::kElfExecutable;
  }
  return FileKind::kElfShared;
}

FileKind ProbeFileKind(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) return FileKind::kMissing;
  if (std::filesystem::is_directory(status)) return FileKind::kDirectory;
  std::ifstream in(path, std::ios::binary);
  if (!in) return FileKind::kMissing;
  std::string head(64 * 1024, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return ClassifyFileBytes(head);
}

yaml::Node BrainToNode(const BrainSpec& brain) {
  if (brain.kind == BrainKind::kBuiltin) return Str("builtin");
  Node n = Node::Mapping();
  n.Set(BrainKindName(brain.kind), Str(brain.path));
  if (brain.kind == BrainKind::kLibrary) n.Set("name", Str(brain.name));
  if (!brain.args.is_null()) n.Set("args", brain.args);
  if (brain.rate_hz > 0) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", brain.rate_hz);
    n.Set("rate_hz", Plain(buf));
  }
  if (brain.offboard.timeout_ms || brain.offboard.hold_ms) {
    Node o = Node::Mapping();
    if (brain.offboard.timeout_ms) o.Set("timeout_ms", Plain(std::to_string(*brain.offboard.timeout_ms)));
    if (brain.offboard.hold_ms) o.Set("hold_ms", Plain(std::to_string(*brain.offboard.hold_ms)));
    n.Set("offboard", std::move(o));
  }
  return n;
}

yaml::Node ComponentToNode(const UserComponentSpec& c) {
  Node n = Node::Mapping();
  n.Set("name", Str(c.name));
  n.Set(ComponentSourceName(c.source), Str(c.ref));
  if (!c.args.empty()) n.Set("args", StringList(c.args));
  if (!c.env.empty()) {
    Node env = Node::Mapping();
    for (const auto& [k, v] : c.env) env.Set(k, Str(v));
    n.Set("env", std::move(env));
  }
  if (!c.networks.empty()) n.Set("networks", StringList(c.networks));
  if (c.priority != 0) n.Set("priority", Plain(std::to_string(c.priority)));
  if (!c.ready.empty()) n.Set("ready", Str(c.ready));
  if (!c.collect.empty()) n.Set("collect", StringList(c.collect));
  return n;
}

}  // namespace swarmbox::dsl
