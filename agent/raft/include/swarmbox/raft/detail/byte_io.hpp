// Little helpers for the compact binary encodings (message codec, mission commands, snapshots,
// WAL records): LEB128 varints, little-endian fixed-width numbers, length-prefixed byte strings.
// ByteReader never reads past its buffer: the first problem latches an error message and every
// later read returns zeros, so a decoder checks ok() once at the end.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>

#include "swarmbox/raft/types.hpp"

namespace swarmbox::raft::detail {

class ByteWriter {
 public:
  explicit ByteWriter(Bytes* out) : out_(out) {}
  void U8(std::uint8_t v) { out_->push_back(v); }
  void Varint(std::uint64_t v) {
    while (v >= 0x80) {
      out_->push_back(static_cast<std::uint8_t>(v | 0x80));
      v >>= 7;
    }
    out_->push_back(static_cast<std::uint8_t>(v));
  }
  void Fixed32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out_->push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void F64(double v) {
    const auto bits = std::bit_cast<std::uint64_t>(v);
    for (int i = 0; i < 8; ++i) out_->push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
  }
  void Blob(std::span<const std::uint8_t> b) {
    Varint(b.size());
    out_->insert(out_->end(), b.begin(), b.end());
  }
  void Str(std::string_view s) {
    Varint(s.size());
    out_->insert(out_->end(), s.begin(), s.end());
  }

 private:
  Bytes* out_;
};

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> in) : in_(in) {}

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  std::size_t offset() const { return pos_; }
  std::size_t remaining() const { return in_.size() - pos_; }
  bool at_end() const { return pos_ == in_.size(); }
  void Fail(std::string what) {
    if (error_.empty()) error_ = std::move(what) + " at byte " + std::to_string(pos_);
  }

  std::uint8_t U8() {
    if (!Need(1, "u8")) return 0;
    return in_[pos_++];
  }
  std::uint64_t Varint() {
    std::uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (!Need(1, "varint")) return 0;
      const std::uint8_t b = in_[pos_++];
      if (shift == 63 && b > 1) break;
      v |= static_cast<std::uint64_t>(b & 0x7F) << shift;
      if ((b & 0x80) == 0) return v;
    }
    Fail("varint overflows 64 bits");
    return 0;
  }
  std::uint32_t Fixed32() {
    if (!Need(4, "fixed32")) return 0;
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(in_[pos_++]) << (8 * i);
    return v;
  }
  double F64() {
    if (!Need(8, "f64")) return 0;
    std::uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits |= static_cast<std::uint64_t>(in_[pos_++]) << (8 * i);
    return std::bit_cast<double>(bits);
  }
  Bytes Blob() {
    const std::uint64_t n = Varint();
    if (!ok() || !Need(n, "bytes")) return {};
    Bytes b(in_.begin() + static_cast<std::ptrdiff_t>(pos_),
            in_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
    pos_ += static_cast<std::size_t>(n);
    return b;
  }
  std::string Str() {
    const std::uint64_t n = Varint();
    if (!ok() || !Need(n, "string")) return {};
    std::string s(reinterpret_cast<const char*>(in_.data()) + pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return s;
  }
  // A count of items that each take at least min_item_bytes: refuses counts the buffer cannot hold.
  std::uint64_t Count(std::size_t min_item_bytes, const char* what) {
    const std::uint64_t n = Varint();
    if (ok() && n > remaining() / (min_item_bytes == 0 ? 1 : min_item_bytes)) {
      Fail(std::string(what) + " count " + std::to_string(n) + " exceeds the message");
      return 0;
    }
    return n;
  }

 private:
  bool Need(std::uint64_t n, const char* what) {
    if (!ok()) return false;
    if (n > remaining()) {
      Fail(std::string("truncated ") + what + " (need " + std::to_string(n) + ", have " +
           std::to_string(remaining()) + ")");
      return false;
    }
    return true;
  }

  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
  std::string error_;
};

// ConfState: voter count, voters, learner count, learners (varints, ascending ids).
inline void WriteConfState(ByteWriter& w, const ConfState& conf) {
  w.Varint(conf.voters.size());
  for (NodeId v : conf.voters) w.Varint(v);
  w.Varint(conf.learners.size());
  for (NodeId l : conf.learners) w.Varint(l);
}

// Reads what WriteConfState wrote; latches an error in `r` for ids that are 0, not ascending, or
// both voter and learner, and for learners without voters.
inline void ReadConfState(ByteReader& r, ConfState* out) {
  ConfState c;
  for (auto* set : {&c.voters, &c.learners}) {
    const std::uint64_t n = r.Count(1, "conf member");
    for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
      const NodeId id = r.Varint();
      if (r.ok() && (id == kNoNode || (!set->empty() && id <= set->back()))) {
        r.Fail("conf member ids must be non-zero and ascending");
      }
      set->push_back(id);
    }
  }
  for (NodeId l : c.learners) {
    if (r.ok() && std::find(c.voters.begin(), c.voters.end(), l) != c.voters.end()) {
      r.Fail("conf node " + std::to_string(l) + " is both voter and learner");
    }
  }
  if (r.ok() && c.voters.empty() && !c.learners.empty()) r.Fail("conf learners without voters");
  if (r.ok()) *out = std::move(c);
}

}  // namespace swarmbox::raft::detail
