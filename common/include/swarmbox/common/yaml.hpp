// A small YAML (and JSON) document tree on libyaml, with source marks on every node.
//
// Every SwarmBox input file (trials, worlds, airframes) and every JSON body from Docker goes
// through here, so that bad input is reported as `file:line:col: message` (ARCHITECTURE.md
// "How a trial flows", step 1). JSON is read with the same parser (JSON is a subset of YAML's
// flow style); EmitJson() writes it back.
//
//   auto doc = yaml::ParseFile("trials/airframes/x500.yaml");
//   if (!doc) return doc.error();            // "x500.yaml:3:7: mapping values are not allowed here"
//   double mass = 0;
//   yaml::MapReader r(*doc);
//   r.Required("mass_kg", &mass).Optional("name", &name);
//   if (auto s = r.Finish(); !s) return s.error();  // also reports unknown keys
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::yaml {

// Where a node starts in its source. line and column are 1-based; line 0 means "built in code".
struct Mark {
  std::string file;
  int line = 0;
  int column = 0;
  std::string ToString() const;  // "file:line:col", or "file" when built in code
};

class Node {
 public:
  enum class Kind { kNull, kScalar, kSequence, kMapping };
  using Entry = std::pair<Node, Node>;

  Node() = default;
  static Node Null(Mark mark = {});
  static Node Scalar(std::string value, Mark mark = {}, bool quoted = false);
  static Node Sequence(Mark mark = {});
  static Node Mapping(Mark mark = {});

  Kind kind() const { return kind_; }
  bool is_null() const { return kind_ == Kind::kNull; }
  bool is_scalar() const { return kind_ == Kind::kScalar; }
  bool is_sequence() const { return kind_ == Kind::kSequence; }
  bool is_mapping() const { return kind_ == Kind::kMapping; }
  const Mark& mark() const { return mark_; }
  std::string Where() const { return mark_.ToString(); }

  // Scalars: the text as written; quoted() tells "1" (a string) from 1 (a number).
  const std::string& scalar() const { return scalar_; }
  bool quoted() const { return quoted_; }

  // Sequences.
  const std::vector<Node>& items() const { return items_; }
  std::vector<Node>& items() { return items_; }
  void Append(Node item) { items_.push_back(std::move(item)); }

  // Mappings keep their source order.
  const std::vector<Entry>& entries() const { return entries_; }
  std::vector<Entry>& entries() { return entries_; }
  const Node* Find(std::string_view key) const;
  Node* Find(std::string_view key);
  // Replaces the value of `key`, or appends it. Returns the stored value.
  Node& Set(std::string_view key, Node value);
  bool Erase(std::string_view key);

  // Typed reads of scalars; errors say where and what was expected.
  Result<std::string> AsString() const;
  Result<double> AsDouble() const;
  Result<std::int64_t> AsInt() const;
  Result<bool> AsBool() const;

  // Structural equality (marks ignored).
  bool operator==(const Node& other) const;

 private:
  Kind kind_ = Kind::kNull;
  Mark mark_;
  std::string scalar_;
  bool quoted_ = false;
  std::vector<Node> items_;
  std::vector<Entry> entries_;
};

// Parses exactly one document (an empty text gives a null node). Errors are kInvalidArgument with
// where = "file:line:col".
Result<Node> Parse(std::string_view text, std::string_view filename = "<string>");
Result<Node> ParseFile(const std::string& path);

// Block-style YAML that Parse() reads back to an equal tree.
std::string Emit(const Node& node);
// JSON. Unquoted scalars that read as numbers, true/false or null are written bare; all others as
// strings. Mappings keep their order.
std::string EmitJson(const Node& node);
// A JSON string literal with escapes, quotes included.
std::string JsonQuote(std::string_view text);

// Plain-scalar resolution shared by the readers: YAML 1.2 core schema booleans/null/numbers.
bool IsNullScalar(const Node& node);
std::optional<bool> ScalarAsBool(std::string_view text);
std::optional<double> ScalarAsDouble(std::string_view text);

// --- decoding into C++ values, used by MapReader ------------------------------------------------
Status Decode(const Node& node, std::string* out);
Status Decode(const Node& node, double* out);
Status Decode(const Node& node, float* out);
Status Decode(const Node& node, int* out);
Status Decode(const Node& node, std::int64_t* out);
Status Decode(const Node& node, std::uint32_t* out);
Status Decode(const Node& node, std::uint64_t* out);
Status Decode(const Node& node, bool* out);

template <typename T>
Status Decode(const Node& node, std::vector<T>* out) {
  if (!node.is_sequence()) {
    return Error(ErrorCode::kInvalidArgument, "expected a list", node.Where());
  }
  out->clear();
  for (const Node& item : node.items()) {
    T value{};
    if (auto s = Decode(item, &value); !s) return s;
    out->push_back(std::move(value));
  }
  return Ok{};
}

template <typename T, std::size_t N>
Status Decode(const Node& node, std::array<T, N>* out) {
  if (!node.is_sequence() || node.items().size() != N) {
    return Error(ErrorCode::kInvalidArgument, "expected a list of " + std::to_string(N) + " values",
                 node.Where());
  }
  for (std::size_t i = 0; i < N; ++i) {
    if (auto s = Decode(node.items()[i], &(*out)[i]); !s) return s;
  }
  return Ok{};
}

template <typename T>
Status Decode(const Node& node, std::optional<T>* out) {
  if (IsNullScalar(node)) {
    out->reset();
    return Ok{};
  }
  T value{};
  if (auto s = Decode(node, &value); !s) return s;
  *out = std::move(value);
  return Ok{};
}

// Reads a mapping against a schema: required and optional keys, and at Finish() an error for the
// first problem met (in call order), including keys the schema does not know.
class MapReader {
 public:
  // `what` names the mapping in messages ("airframe", "drone"...).
  explicit MapReader(const Node& node, std::string what = "mapping");

  template <typename T>
  MapReader& Required(std::string_view key, T* out) {
    if (const Node* n = Take(key, /*required=*/true)) Keep(Decode(*n, out), key);
    return *this;
  }
  // Leaves *out untouched (its default) when the key is absent.
  template <typename T>
  MapReader& Optional(std::string_view key, T* out) {
    if (const Node* n = Take(key, /*required=*/false)) Keep(Decode(*n, out), key);
    return *this;
  }
  // The raw child, for nested structures; marks the key as known. nullptr when absent.
  const Node* Child(std::string_view key, bool required = false) { return Take(key, required); }
  // Records an error found by the caller while reading this mapping.
  void Fail(Error error);

  bool ok() const { return !first_error_.has_value(); }
  Status Finish();

 private:
  const Node* Take(std::string_view key, bool required);
  void Keep(Status status, std::string_view key);

  const Node& node_;
  std::string what_;
  std::vector<std::string> known_;
  std::optional<Error> first_error_;
};

}  // namespace swarmbox::yaml
