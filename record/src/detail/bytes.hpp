// Little-endian serialisation of MCAP's field types (https://mcap.dev/spec#serialization):
// fixed-width unsigned integers, uint32-length-prefixed strings and byte strings, and the bounds-
// checked reader the McapReader parses records with. Pure: no I/O.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace swarmbox::record::detail {

// Appends to a std::string used as a byte buffer.
class ByteWriter {
 public:
  explicit ByteWriter(std::string* out) : out_(out) {}

  void U8(std::uint8_t v) { out_->push_back(static_cast<char>(v)); }
  void U16(std::uint16_t v) { Le(v, 2); }
  void U32(std::uint32_t v) { Le(v, 4); }
  void U64(std::uint64_t v) { Le(v, 8); }
  // String and the uint32-prefixed Bytes of the Schema record: <uint32 length><bytes>.
  void Str(std::string_view s) {
    U32(static_cast<std::uint32_t>(s.size()));
    out_->append(s);
  }
  void Raw(std::string_view s) { out_->append(s); }
  // Overwrites 8 bytes at `at` (a length prefix written before its content was known).
  void PatchU64(std::size_t at, std::uint64_t v) { Put(at, v, 8); }
  std::size_t size() const { return out_->size(); }

 private:
  void Le(std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) out_->push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
  }
  void Put(std::size_t at, std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) {
      (*out_)[at + static_cast<std::size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xffu);
    }
  }
  std::string* out_;
};

inline std::uint64_t LoadLe(const char* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}

// Reads fields from a view; every read checks the bounds, and the first short read makes ok()
// false for good (the caller checks once after a record's fields).
class ByteReader {
 public:
  explicit ByteReader(std::string_view data) : data_(data) {}

  std::uint8_t U8() { return static_cast<std::uint8_t>(Fixed(1)); }
  std::uint16_t U16() { return static_cast<std::uint16_t>(Fixed(2)); }
  std::uint32_t U32() { return static_cast<std::uint32_t>(Fixed(4)); }
  std::uint64_t U64() { return Fixed(8); }
  std::string_view Str() { return Take(U32()); }
  std::string_view Take(std::uint64_t n) {
    if (!ok_ || n > data_.size() - pos_) {
      ok_ = false;
      return {};
    }
    std::string_view s = data_.substr(pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return s;
  }

  bool ok() const { return ok_; }
  std::size_t pos() const { return pos_; }
  std::size_t remaining() const { return ok_ ? data_.size() - pos_ : 0; }

 private:
  std::uint64_t Fixed(int bytes) {
    std::string_view s = Take(static_cast<std::uint64_t>(bytes));
    return ok_ ? LoadLe(s.data(), bytes) : 0;
  }
  std::string_view data_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

}  // namespace swarmbox::record::detail
