// The MCAP container's constants (opcodes, magic) and its two byte transforms: CRC32 (zlib's
// crc32, the polynomial the spec names) and chunk compression (zstd, lz4 frames, none).
// Spec: https://mcap.dev/spec and https://mcap.dev/spec/registry#compression-formats.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/record/mcap.hpp"

namespace swarmbox::record::detail {

// 0x89 "MCAP" '0' "\r\n": major version 0.
inline constexpr std::string_view kMagic{"\x89MCAP0\r\n", 8};

enum class Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

inline constexpr std::size_t kRecordPrefixBytes = 1 + 8;  // opcode, uint64 content length
// Footer content: summary_start, summary_offset_start, summary_crc.
inline constexpr std::size_t kFooterContentBytes = 8 + 8 + 4;
inline constexpr std::size_t kFooterRecordBytes = kRecordPrefixBytes + kFooterContentBytes;
inline constexpr std::size_t kDataEndRecordBytes = kRecordPrefixBytes + 4;

// CRC-32 (ISO-HDLC, zlib's). Pass the previous value to continue over more bytes; start with 0.
std::uint32_t Crc32(std::string_view bytes, std::uint32_t crc = 0);

// The chunk `compression` field: "zstd", "lz4", "".
std::string_view CompressionField(Compression c);

// Reuses its compression contexts across chunks. Not thread-safe.
class Compressor {
 public:
  Compressor();
  ~Compressor();
  Compressor(const Compressor&) = delete;
  Compressor& operator=(const Compressor&) = delete;
  // Replaces *out with `in` compressed by `c` (kInternal when the library fails).
  Status Compress(Compression c, std::string_view in, std::string* out);

 private:
  void* zstd_ = nullptr;  // ZSTD_CCtx
};

// Decompresses a chunk's records. `compression` is the chunk's field; `uncompressed_size` what the
// chunk says it holds (the result must have exactly that size; at most 1 GiB). kProtocol for an
// unknown compression, a corrupt stream or a size over the limit.
Status Decompress(std::string_view compression, std::string_view in, std::uint64_t uncompressed_size,
                  std::string* out);

}  // namespace swarmbox::record::detail
