// McapWriter / McapReader: the MCAP container (https://mcap.dev/spec) for JSON channels: chunked,
// indexed, with a summary and CRCs, zstd (default) or lz4 compressed, so Foxglove and the mcap
// tools open a recording as it is.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "swarmbox/record/sink.hpp"

namespace swarmbox::record {

enum class Compression { kNone, kZstd, kLz4 };

// "none", "zstd", "lz4" (the names a trial or a command line uses).
std::string_view CompressionName(Compression c);
// The inverse of CompressionName; kInvalidArgument naming the accepted values otherwise.
Result<Compression> ParseCompression(std::string_view name);

struct McapOptions {
  Compression compression = Compression::kZstd;
  std::size_t chunk_bytes = 1u << 20;  // uncompressed bytes per chunk before it is closed
  std::string profile;                 // MCAP header profile ("" for JSON channels)
};

class McapWriter final : public Sink {
 public:
  static Result<std::unique_ptr<McapWriter>> Create(const std::string& path, McapOptions options = {});
  ~McapWriter() override;  // closes if Close() was not called (errors then go to stderr)

  Result<ChannelId> AddChannel(const ChannelSpec& spec) override;
  Status Write(ChannelId channel, std::uint64_t log_time_ns, std::string_view json) override;
  // Last chunk, DataEnd, Summary, SummaryOffset, Footer. Writes after Close() fail.
  Status Close();

 private:
  struct Impl;
  explicit McapWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

struct McapMessage {
  ChannelId channel = 0;
  std::uint64_t log_time_ns = 0;
  std::string data;
};

// Reads indexed MCAP files (a summary with ChunkIndex and Statistics records, as McapWriter, the
// mcap CLI and Foxglove write them) whose messages are in chunks. Errors: kIo when the file cannot
// be read; kProtocol for anything malformed, a CRC that does not match (data section, summary,
// chunk), a chunk that does not decompress, or a file without footer (a writer that never closed
// it: the process died); the message says which and where (byte offsets).
class McapReader {
 public:
  // Reads the header, footer and summary; checks the summary CRC and the data section CRC (one
  // pass over the file).
  static Result<McapReader> Open(const std::string& path);

  const std::string& profile() const { return profile_; }
  const std::string& library() const { return library_; }  // the writer's name, e.g. "swarmbox 0.1.0"
  std::size_t chunk_count() const { return chunks_.size(); }

  const std::vector<ChannelSpec>& channels() const { return channels_; }  // index = ChannelId
  std::uint64_t message_count() const { return message_count_; }
  std::uint64_t start_ns() const { return start_ns_; }
  std::uint64_t end_ns() const { return end_ns_; }
  // Every message in log-time order (ties: file order), decompressing one chunk at a time and
  // checking each chunk's CRC; memory holds the chunks whose time ranges overlap.
  Status ForEach(const std::function<void(const McapMessage&)>& fn) const;

 private:
  struct ChunkRef {
    std::uint64_t start_ns = 0;
    std::uint64_t offset = 0;  // of the Chunk record from the start of the file
    std::uint64_t length = 0;  // of the Chunk record, opcode and length included
  };
  std::string path_;
  std::string profile_;
  std::string library_;
  std::vector<ChunkRef> chunks_;                                // ordered by (start_ns, offset)
  std::unordered_map<std::uint16_t, ChannelId> channel_index_;  // MCAP channel id -> ChannelId
  std::vector<ChannelSpec> channels_;
  std::uint64_t message_count_ = 0;
  std::uint64_t start_ns_ = 0;
  std::uint64_t end_ns_ = 0;
};

}  // namespace swarmbox::record
