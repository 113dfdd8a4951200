#include "swarmbox/common/yaml.hpp"

#include <yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>

#include "detail/backslash_escape.hpp"

namespace swarmbox::yaml {

std::string Mark::ToString() const {
  if (line <= 0) return file.empty() ? std::string("<built-in>") : file;
  return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

Node Node::Null(Mark mark) {
  Node n;
  n.kind_ = Kind::kNull;
  n.mark_ = std::move(mark);
  return n;
}

Node Node::Scalar(std::string value, Mark mark, bool quoted) {
  Node n;
  n.kind_ = Kind::kScalar;
  n.scalar_ = std::move(value);
  n.mark_ = std::move(mark);
  n.quoted_ = quoted;
  return n;
}

Node Node::Sequence(Mark mark) {
  Node n;
  n.kind_ = Kind::kSequence;
  n.mark_ = std::move(mark);
  return n;
}

Node Node::Mapping(Mark mark) {
  Node n;
  n.kind_ = Kind::kMapping;
  n.mark_ = std::move(mark);
  return n;
}

const Node* Node::Find(std::string_view key) const {
  for (const auto& [k, v] : entries_) {
    if (k.is_scalar() && k.scalar() == key) return &v;
  }
  return nullptr;
}

Node* Node::Find(std::string_view key) {
  for (auto& [k, v] : entries_) {
    if (k.is_scalar() && k.scalar() == key) return &v;
  }
  return nullptr;
}

Node& Node::Set(std::string_view key, Node value) {
  if (kind_ != Kind::kMapping) {
    SWARMBOX_CHECK(kind_ == Kind::kNull);
    kind_ = Kind::kMapping;
  }
  if (Node* existing = Find(key)) {
    *existing = std::move(value);
    return *existing;
  }
  entries_.emplace_back(Scalar(std::string(key)), std::move(value));
  return entries_.back().second;
}

bool Node::Erase(std::string_view key) {
  auto it = std::find_if(entries_.begin(), entries_.end(),
                         [&](const Entry& e) { return e.first.is_scalar() && e.first.scalar() == key; });
  if (it == entries_.end()) return false;
  entries_.erase(it);
  return true;
}

bool Node::operator==(const Node& other) const {
  if (kind_ != other.kind_) return false;
  switch (kind_) {
    case Kind::kNull:
      return true;
    case Kind::kScalar:
      return scalar_ == other.scalar_ && quoted_ == other.quoted_;
    case Kind::kSequence:
      return items_ == other.items_;
    case Kind::kMapping:
      return entries_ == other.entries_;
  }
  return false;
}

// --- scalar resolution ---------------------------------------------------------------------------

bool IsNullScalar(const Node& node) {
  if (node.is_null()) return true;
  if (!node.is_scalar() || node.quoted()) return false;
  const std::string& s = node.scalar();
  return s.empty() || s == "~" || s == "null" || s == "Null" || s == "NULL";
}

std::optional<bool> ScalarAsBool(std::string_view text) {
  if (text == "true" || text == "True" || text == "TRUE") return true;
  if (text == "false" || text == "False" || text == "FALSE") return false;
  return std::nullopt;
}

std::optional<double> ScalarAsDouble(std::string_view text) {
  if (text.empty()) return std::nullopt;
  if (text == ".inf" || text == "+.inf" || text == ".Inf") return std::numeric_limits<double>::infinity();
  if (text == "-.inf" || text == "-.Inf") return -std::numeric_limits<double>::infinity();
  if (text == ".nan" || text == ".NaN") return std::numeric_limits<double>::quiet_NaN();
  // Only decimal notation (YAML 1.2 core schema); no hex floats, no "inf" words, no leading space.
  for (char c : text) {
    if (!((c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E' || c == '_')) {
      return std::nullopt;
    }
  }
  std::string clean;
  clean.reserve(text.size());
  for (char c : text) {
    if (c != '_') clean.push_back(c);
  }
  errno = 0;
  char* end = nullptr;
  double v = std::strtod(clean.c_str(), &end);
  if (end != clean.c_str() + clean.size() || errno == ERANGE) return std::nullopt;
  return v;
}

namespace {

Error TypeError(const Node& node, std::string_view expected) {
  std::string got;
  switch (node.kind()) {
    case Node::Kind::kNull:
      got = "nothing";
      break;
    case Node::Kind::kScalar:
      got = "'" + node.scalar() + "'";
      break;
    case Node::Kind::kSequence:
      got = "a list";
      break;
    case Node::Kind::kMapping:
      got = "a mapping";
      break;
  }
  return Error(ErrorCode::kInvalidArgument, "expected " + std::string(expected) + ", got " + got,
               node.Where());
}

}  // namespace

Result<std::string> Node::AsString() const {
  if (kind_ != Kind::kScalar) return TypeError(*this, "a string");
  return scalar_;
}

Result<double> Node::AsDouble() const {
  if (kind_ != Kind::kScalar || quoted_) return TypeError(*this, "a number");
  auto v = ScalarAsDouble(scalar_);
  if (!v) return TypeError(*this, "a number");
  return *v;
}

Result<std::int64_t> Node::AsInt() const {
  if (kind_ != Kind::kScalar || quoted_) return TypeError(*this, "an integer");
  const std::string& s = scalar_;
  if (s.empty()) return TypeError(*this, "an integer");
  std::size_t i = (s[0] == '-' || s[0] == '+') ? 1 : 0;
  if (i == s.size()) return TypeError(*this, "an integer");
  for (std::size_t j = i; j < s.size(); ++j) {
    if (s[j] < '0' || s[j] > '9') return TypeError(*this, "an integer");
  }
  errno = 0;
  char* end = nullptr;
  long long v = std::strtoll(s.c_str(), &end, 10);
  if (errno == ERANGE) {
    return Error(ErrorCode::kInvalidArgument, "integer '" + s + "' is out of range", Where());
  }
  return static_cast<std::int64_t>(v);
}

Result<bool> Node::AsBool() const {
  if (kind_ != Kind::kScalar || quoted_) return TypeError(*this, "true or false");
  auto v = ScalarAsBool(scalar_);
  if (!v) return TypeError(*this, "true or false");
  return *v;
}

// --- parsing -------------------------------------------------------------------------------------

namespace {

class Builder {
 public:
  Builder(std::string_view text, std::string file) : file_(std::move(file)) {
    yaml_parser_initialize(&parser_);
    yaml_parser_set_input_string(&parser_, reinterpret_cast<const unsigned char*>(text.data()),
                                 text.size());
  }
  ~Builder() { yaml_parser_delete(&parser_); }
  Builder(const Builder&) = delete;
  Builder& operator=(const Builder&) = delete;

  Result<Node> Run() {
    yaml_event_t event;
    bool have_document = false;
    Node root = Node::Null(Mark{file_, 1, 1});
    while (true) {
      if (!yaml_parser_parse(&parser_, &event)) return ParserError();
      const yaml_event_type_t type = event.type;
      if (type == YAML_STREAM_END_EVENT) {
        yaml_event_delete(&event);
        break;
      }
      if (type == YAML_DOCUMENT_START_EVENT) {
        if (have_document) {
          Mark m = MarkOf(event.start_mark);
          yaml_event_delete(&event);
          return Error(ErrorCode::kInvalidArgument, "expected a single document, found another",
                       m.ToString());
        }
        have_document = true;
        yaml_event_delete(&event);
        auto node = ParseNode();
        if (!node) return node.error();
        root = std::move(*node);
        // DOCUMENT_END
        if (!yaml_parser_parse(&parser_, &event)) return ParserError();
        yaml_event_delete(&event);
        continue;
      }
      yaml_event_delete(&event);  // STREAM_START
    }
    return root;
  }

 private:
  Mark MarkOf(const yaml_mark_t& m) const {
    return Mark{file_, static_cast<int>(m.line) + 1, static_cast<int>(m.column) + 1};
  }

  Error ParserError() const {
    Mark m = MarkOf(parser_.problem_mark);
    std::string msg = parser_.problem ? parser_.problem : "malformed YAML";
    if (parser_.context) msg = std::string(parser_.context) + ": " + msg;
    return Error(ErrorCode::kInvalidArgument, msg, m.ToString());
  }

  // Parses the node whose first event comes next.
  Result<Node> ParseNode() {
    yaml_event_t event;
    if (!yaml_parser_parse(&parser_, &event)) return ParserError();
    Result<Node> out = FromEvent(event);
    yaml_event_delete(&event);
    return out;
  }

  Result<Node> FromEvent(yaml_event_t& event) {
    const Mark mark = MarkOf(event.start_mark);
    switch (event.type) {
      case YAML_SCALAR_EVENT: return FromScalar(event, mark);
      case YAML_SEQUENCE_START_EVENT: return ParseSequence(mark);
      case YAML_MAPPING_START_EVENT: return ParseMapping(mark);
      case YAML_ALIAS_EVENT:
        return Error(ErrorCode::kInvalidArgument, "YAML aliases (*name) are not supported", mark.ToString());
      default:
        return Error(ErrorCode::kInvalidArgument, "unexpected YAML structure", mark.ToString());
    }
  }

  static Node FromScalar(const yaml_event_t& event, const Mark& mark) {
    const auto& scalar = event.data.scalar;
    std::string value(reinterpret_cast<const char*>(scalar.value), scalar.length);
    const bool quoted = scalar.style == YAML_SINGLE_QUOTED_SCALAR_STYLE ||
                        scalar.style == YAML_DOUBLE_QUOTED_SCALAR_STYLE ||
                        scalar.style == YAML_LITERAL_SCALAR_STYLE || scalar.style == YAML_FOLDED_SCALAR_STYLE;
    Node n = Node::Scalar(std::move(value), mark, quoted);
    if (!quoted && IsNullScalar(n)) return Node::Null(mark);
    return n;
  }

  // The next item of the sequence or mapping being read (a mapping's key), or nullopt at its
  // `end` event.
  Result<std::optional<Node>> ParseItem(yaml_event_type_t end) {
    yaml_event_t event;
    if (!yaml_parser_parse(&parser_, &event)) return ParserError();
    if (event.type == end) {
      yaml_event_delete(&event);
      return std::optional<Node>();
    }
    Result<Node> item = FromEvent(event);
    yaml_event_delete(&event);
    if (!item) return item.error();
    return std::optional<Node>(std::move(*item));
  }

  Result<Node> ParseSequence(const Mark& mark) {
    Node seq = Node::Sequence(mark);
    while (true) {
      Result<std::optional<Node>> item = ParseItem(YAML_SEQUENCE_END_EVENT);
      if (!item) return item.error();
      if (!*item) return seq;
      seq.Append(std::move(**item));
    }
  }

  Result<Node> ParseMapping(const Mark& mark) {
    Node map = Node::Mapping(mark);
    while (true) {
      Result<std::optional<Node>> key = ParseItem(YAML_MAPPING_END_EVENT);
      if (!key) return key.error();
      if (!*key) return map;
      const Node& k = **key;
      if (!k.is_scalar()) {
        return Error(ErrorCode::kInvalidArgument, "mapping keys must be plain strings", k.Where());
      }
      if (map.Find(k.scalar()) != nullptr) {
        return Error(ErrorCode::kInvalidArgument, "duplicate key '" + k.scalar() + "'", k.Where());
      }
      Result<Node> value = ParseNode();
      if (!value) return value.error();
      map.entries().emplace_back(std::move(**key), std::move(*value));
    }
  }

  std::string file_;
  yaml_parser_t parser_{};
};

}  // namespace

Result<Node> Parse(std::string_view text, std::string_view filename) {
  Builder builder(text, std::string(filename));
  return builder.Run();
}

Result<Node> ParseFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return Error(ErrorCode::kNotFound, std::string("cannot open file: ") + std::strerror(errno), path);
  }
  std::ostringstream buf;
  buf << in.rdbuf();
  if (in.bad()) return Error(ErrorCode::kIo, "read failed", path);
  return Parse(buf.str(), path);
}

// --- emitting ------------------------------------------------------------------------------------

std::string JsonQuote(std::string_view text) {
  std::string out;
  out.reserve(text.size() + 2);
  out.push_back('"');
  for (char ch : text) {
    if (const std::string_view escape = detail::BackslashEscape(ch); !escape.empty()) {
      out += escape;
      continue;
    }
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      default:
        if (c < 0x20 || c == 0x7f) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out.push_back(static_cast<char>(c));
        }
    }
  }
  out.push_back('"');
  return out;
}

namespace {

bool IsBareJsonScalar(const Node& n) {
  if (n.quoted()) return false;
  const std::string& s = n.scalar();
  if (ScalarAsBool(s)) return true;
  auto d = ScalarAsDouble(s);
  if (!d || !std::isfinite(*d)) return false;
  // JSON numbers: no leading '+', no '_' separators, no leading '.', no trailing '.'.
  if (s[0] == '+' || s[0] == '.' || s.back() == '.' || s.find('_') != std::string::npos) return false;
  if (s.size() > 1 && s[0] == '0' && s[1] != '.' && s[1] != 'e' && s[1] != 'E') return false;
  if (s.size() > 2 && s[0] == '-' && s[1] == '0' && s[2] != '.' && s[2] != 'e' && s[2] != 'E') return false;
  return true;
}

void EmitJsonTo(const Node& n, std::string& out) {
  switch (n.kind()) {
    case Node::Kind::kNull:
      out += "null";
      return;
    case Node::Kind::kScalar: {
      if (IsBareJsonScalar(n)) {
        auto b = ScalarAsBool(n.scalar());
        out += b ? (*b ? "true" : "false") : n.scalar();
      } else {
        out += JsonQuote(n.scalar());
      }
      return;
    }
    case Node::Kind::kSequence: {
      out.push_back('[');
      bool first = true;
      for (const Node& item : n.items()) {
        if (!first) out.push_back(',');
        first = false;
        EmitJsonTo(item, out);
      }
      out.push_back(']');
      return;
    }
    case Node::Kind::kMapping: {
      out.push_back('{');
      bool first = true;
      for (const auto& [k, v] : n.entries()) {
        if (!first) out.push_back(',');
        first = false;
        out += JsonQuote(k.scalar());
        out.push_back(':');
        EmitJsonTo(v, out);
      }
      out.push_back('}');
      return;
    }
  }
}

// A plain scalar is safe when it reads back as the same text with the same type.
bool NeedsQuotes(const Node& n) {
  const std::string& s = n.scalar();
  if (s.empty()) return true;
  if (n.quoted()) return true;
  static constexpr std::string_view kSpecial = ":#{}[],&*!|>'\"%@`\n\t";
  if (s.find_first_of(kSpecial) != std::string::npos) return true;
  if (s.front() == ' ' || s.back() == ' ' || s.front() == '-' || s.front() == '?') {
    return !(ScalarAsDouble(s).has_value());
  }
  return false;
}

void EmitYamlScalar(const Node& n, std::string& out) {
  if (n.is_null()) {
    out += "null";
  } else if (NeedsQuotes(n)) {
    out += JsonQuote(n.scalar());  // a JSON string is a valid YAML double-quoted scalar
  } else {
    out += n.scalar();
  }
}

bool IsEmptyCollection(const Node& n) {
  return (n.is_sequence() && n.items().empty()) || (n.is_mapping() && n.entries().empty());
}

void EmitYamlTo(const Node& n, int indent, std::string& out) {
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  if (n.is_mapping()) {
    for (const auto& [k, v] : n.entries()) {
      out += pad;
      EmitYamlScalar(k, out);
      out.push_back(':');
      if ((v.is_mapping() || v.is_sequence()) && !IsEmptyCollection(v)) {
        out.push_back('\n');
        EmitYamlTo(v, indent + 2, out);
      } else {
        out.push_back(' ');
        if (v.is_sequence()) out += "[]";
        else if (v.is_mapping()) out += "{}";
        else EmitYamlScalar(v, out);
        out.push_back('\n');
      }
    }
  } else if (n.is_sequence()) {
    for (const Node& item : n.items()) {
      out += pad;
      out += "-";
      if ((item.is_mapping() || item.is_sequence()) && !IsEmptyCollection(item)) {
        out.push_back('\n');
        EmitYamlTo(item, indent + 2, out);
      } else {
        out.push_back(' ');
        if (item.is_sequence()) out += "[]";
        else if (item.is_mapping()) out += "{}";
        else EmitYamlScalar(item, out);
        out.push_back('\n');
      }
    }
  } else {
    out += pad;
    EmitYamlScalar(n, out);
    out.push_back('\n');
  }
}

}  // namespace

std::string EmitJson(const Node& node) {
  std::string out;
  EmitJsonTo(node, out);
  return out;
}

std::string Emit(const Node& node) {
  std::string out;
  if (IsEmptyCollection(node)) return node.is_sequence() ? "[]\n" : "{}\n";
  EmitYamlTo(node, 0, out);
  return out;
}

// --- decoding ------------------------------------------------------------------------------------

Status Decode(const Node& node, std::string* out) {
  auto v = node.AsString();
  if (!v) return v.error();
  *out = std::move(*v);
  return Ok{};
}

Status Decode(const Node& node, double* out) {
  auto v = node.AsDouble();
  if (!v) return v.error();
  *out = *v;
  return Ok{};
}

Status Decode(const Node& node, float* out) {
  auto v = node.AsDouble();
  if (!v) return v.error();
  *out = static_cast<float>(*v);
  return Ok{};
}

namespace {

template <typename T>
Status DecodeInteger(const Node& node, T* out) {
  auto v = node.AsInt();
  if (!v) return v.error();
  if (*v < static_cast<std::int64_t>(std::numeric_limits<T>::min()) ||
      (*v > 0 && static_cast<std::uint64_t>(*v) > static_cast<std::uint64_t>(std::numeric_limits<T>::max()))) {
    return Error(ErrorCode::kInvalidArgument,
                 "integer " + std::to_string(*v) + " is out of range [" +
                     std::to_string(std::numeric_limits<T>::min()) + ", " +
                     std::to_string(std::numeric_limits<T>::max()) + "]",
                 node.Where());
  }
  *out = static_cast<T>(*v);
  return Ok{};
}

}  // namespace

Status Decode(const Node& node, int* out) { return DecodeInteger(node, out); }
Status Decode(const Node& node, std::int64_t* out) { return DecodeInteger(node, out); }
Status Decode(const Node& node, std::uint32_t* out) { return DecodeInteger(node, out); }
Status Decode(const Node& node, std::uint64_t* out) { return DecodeInteger(node, out); }

Status Decode(const Node& node, bool* out) {
  auto v = node.AsBool();
  if (!v) return v.error();
  *out = *v;
  return Ok{};
}

// --- MapReader -----------------------------------------------------------------------------------

MapReader::MapReader(const Node& node, std::string what) : node_(node), what_(std::move(what)) {
  if (!node_.is_mapping()) {
    first_error_ = Error(ErrorCode::kInvalidArgument,
                         "expected " + what_ + " to be a mapping of key: value", node_.Where());
  }
}

namespace {

// Issue #21 spelled each unit one way: m/s `_m_s`, m/s^2 `_m_s2`, rad/s `_rad_s`, deg/s `_deg_s`.
// A key in the old spelling (`speed` + `_mps`) is the key of today in the new one; empty if `key`
// has no old unit suffix. (The suffixes stand alone in these strings so that the rename script,
// which rewrites `<name>_mps`, leaves them as they are.)
std::string RespelledUnitKey(std::string_view key) {
  static constexpr std::pair<std::string_view, std::string_view> kOldToNew[] = {
      {"_mps", "_m_s"},     {"_mps2", "_m_s2"},     {"_radps", "_rad_s"},
      {"_radps2", "_rad_s2"}, {"_degps", "_deg_s"}, {"_degps2", "_deg_s2"}};
  for (const auto& [old_suffix, new_suffix] : kOldToNew) {
    if (key.size() > old_suffix.size() && key.ends_with(old_suffix)) {
      return std::string(key.substr(0, key.size() - old_suffix.size())) + std::string(new_suffix);
    }
  }
  return {};
}

// The key of `map` that is `key` in the units' old spelling; nullptr if none.
const Node* OldSpellingOf(const Node& map, std::string_view key) {
  for (const auto& [k, v] : map.entries()) {
    if (RespelledUnitKey(k.scalar()) == key) return &k;
  }
  return nullptr;
}

// The error for `old`, a key in the units' old spelling of `key`, in the mapping `what`.
Error RespelledKeyError(const Node& old, std::string_view key, const std::string& what) {
  return Error(ErrorCode::kInvalidArgument,
               "unknown key '" + old.scalar() + "' in " + what + ": it is spelled '" + std::string(key) +
                   "' now (units are spelled _m_s, _m_s2, _rad_s, _deg_s)",
               old.Where());
}

}  // namespace

const Node* MapReader::Take(std::string_view key, bool required) {
  known_.emplace_back(key);
  if (!node_.is_mapping()) return nullptr;
  const Node* child = node_.Find(key);
  if (child == nullptr && required && !first_error_) {
    if (const Node* old = OldSpellingOf(node_, key)) {
      first_error_ = RespelledKeyError(*old, key, what_);
    } else {
      first_error_ = Error(ErrorCode::kInvalidArgument,
                           "missing required key '" + std::string(key) + "' in " + what_, node_.Where());
    }
  }
  return child;
}

void MapReader::Keep(Status status, std::string_view key) {
  if (!status && !first_error_) {
    first_error_ = Error(status.error().code(),
                         "'" + std::string(key) + "': " + status.error().message(), status.error().where());
  }
}

void MapReader::Fail(Error error) {
  if (!first_error_) first_error_ = std::move(error);
}

Status MapReader::Finish() {
  if (first_error_) return *first_error_;
  for (const auto& [k, v] : node_.entries()) {
    if (std::find(known_.begin(), known_.end(), k.scalar()) == known_.end()) {
      const std::string respelled = RespelledUnitKey(k.scalar());
      if (!respelled.empty() && std::find(known_.begin(), known_.end(), respelled) != known_.end()) {
        return RespelledKeyError(k, respelled, what_);
      }
      std::string accepted;
      for (const auto& name : known_) accepted += (accepted.empty() ? "" : ", ") + name;
      return Error(ErrorCode::kInvalidArgument,
                   "unknown key '" + k.scalar() + "' in " + what_ + " (accepted: " + accepted + ")",
                   k.Where());
    }
  }
  return Ok{};
}

}  // namespace swarmbox::yaml
