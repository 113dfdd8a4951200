#include "detail/mcap_format.hpp"

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <string>

namespace swarmbox::record::detail {

namespace {
// A corrupt size field must not make the reader allocate without bound; real chunks are ~1 MiB.
constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 30;
// zstd's default level: ~5x on the recording's JSON at a few hundred MB/s per core.
constexpr int kZstdLevel = 3;
}  // namespace

std::uint32_t Crc32(std::string_view bytes, std::uint32_t crc) {
  uLong c = crc;
  const auto* p = reinterpret_cast<const Bytef*>(bytes.data());
  std::size_t left = bytes.size();
  while (left > 0) {  // zlib's length is a uInt: feed at most 1 GiB at a time
    const auto n = static_cast<uInt>(std::min<std::size_t>(left, std::size_t{1} << 30));
    c = crc32(c, p, n);
    p += n;
    left -= n;
  }
  return static_cast<std::uint32_t>(c);
}

std::string_view CompressionField(Compression c) {
  // MCAP's field is the name, except "" for none.
  return c == Compression::kZstd || c == Compression::kLz4 ? CompressionName(c) : std::string_view();
}

Compressor::Compressor() = default;

Compressor::~Compressor() {
  if (zstd_ != nullptr) ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(zstd_));
}

Status Compressor::Compress(Compression c, std::string_view in, std::string* out) {
  switch (c) {
    case Compression::kNone:
      out->assign(in);
      return Ok{};
    case Compression::kZstd: {
      if (zstd_ == nullptr) zstd_ = ZSTD_createCCtx();
      if (zstd_ == nullptr) return Error(ErrorCode::kInternal, "ZSTD_createCCtx failed", "zstd");
      out->resize(ZSTD_compressBound(in.size()));
      const std::size_t n = ZSTD_compressCCtx(static_cast<ZSTD_CCtx*>(zstd_), out->data(), out->size(),
                                              in.data(), in.size(), kZstdLevel);
      if (ZSTD_isError(n)) return Error(ErrorCode::kInternal, ZSTD_getErrorName(n), "ZSTD_compressCCtx");
      out->resize(n);
      return Ok{};
    }
    case Compression::kLz4: {
      // A complete LZ4 frame (the format MCAP's "lz4" names) that records its content size.
      LZ4F_preferences_t prefs{};
      prefs.frameInfo.contentSize = in.size();
      prefs.frameInfo.blockSizeID = LZ4F_max4MB;
      out->resize(LZ4F_compressFrameBound(in.size(), &prefs));
      const std::size_t n = LZ4F_compressFrame(out->data(), out->size(), in.data(), in.size(), &prefs);
      if (LZ4F_isError(n)) return Error(ErrorCode::kInternal, LZ4F_getErrorName(n), "LZ4F_compressFrame");
      out->resize(n);
      return Ok{};
    }
  }
  return Error(ErrorCode::kInvalidArgument, "unknown compression");
}

namespace {

Status DecompressLz4(std::string_view in, std::string* out) {
  LZ4F_dctx* dctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&dctx, LZ4F_VERSION))) {
    return Error(ErrorCode::kInternal, "LZ4F_createDecompressionContext failed", "lz4");
  }
  const char* src = in.data();
  std::size_t src_left = in.size();
  std::size_t produced = 0;
  std::size_t hint = 1;
  while (src_left > 0 && hint != 0) {
    std::size_t dst_size = out->size() - produced;
    std::size_t src_size = src_left;
    hint = LZ4F_decompress(dctx, out->data() + produced, &dst_size, src, &src_size, nullptr);
    if (LZ4F_isError(hint)) {
      std::string why = LZ4F_getErrorName(hint);
      LZ4F_freeDecompressionContext(dctx);
      return Error(ErrorCode::kProtocol, "corrupt lz4 chunk: " + why, "lz4");
    }
    produced += dst_size;
    src += src_size;
    src_left -= src_size;
    if (src_size == 0 && dst_size == 0) break;  // no progress: the output is full or input ends early
  }
  LZ4F_freeDecompressionContext(dctx);
  if (hint != 0 || produced != out->size()) {
    return Error(ErrorCode::kProtocol, "lz4 chunk ends early or holds more than its uncompressed size", "lz4");
  }
  return Ok{};
}

}  // namespace

Status Decompress(std::string_view compression, std::string_view in, std::uint64_t uncompressed_size,
                  std::string* out) {
  if (uncompressed_size > kMaxChunkBytes) {
    return Error(ErrorCode::kProtocol, "chunk uncompressed size " + std::to_string(uncompressed_size) +
                                           " exceeds the reader's limit of " + std::to_string(kMaxChunkBytes));
  }
  const auto size = static_cast<std::size_t>(uncompressed_size);
  if (compression.empty()) {
    if (in.size() != size) {
      return Error(ErrorCode::kProtocol, "uncompressed chunk: records size differs from uncompressed_size");
    }
    out->assign(in);
    return Ok{};
  }
  out->resize(size);
  if (compression == "zstd") {
    const std::size_t n = ZSTD_decompress(out->data(), out->size(), in.data(), in.size());
    if (ZSTD_isError(n)) {
      return Error(ErrorCode::kProtocol, std::string("corrupt zstd chunk: ") + ZSTD_getErrorName(n), "zstd");
    }
    if (n != size) return Error(ErrorCode::kProtocol, "zstd chunk holds fewer bytes than its uncompressed size");
    return Ok{};
  }
  if (compression == "lz4") return DecompressLz4(in, out);
  return Error(ErrorCode::kProtocol, "unsupported chunk compression \"" + std::string(compression) + "\"");
}

}  // namespace swarmbox::record::detail
