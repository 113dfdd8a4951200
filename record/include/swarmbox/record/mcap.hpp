// McapWriter / McapReader: the MCAP container (https://mcap.dev/spec) for JSON channels: chunked,
// indexed, with a summary and CRCs, zstd (default) or lz4 compressed, so Foxglove and the mcap
// tools open a recording as it is.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "swarmbox/record/sink.hpp"

namespace swarmbox::record {

enum class Compression { kNone, kZstd, kLz4 };

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

class McapReader {
 public:
  // Reads the summary, checks the CRCs the file carries.
  static Result<McapReader> Open(const std::string& path);

  const std::vector<ChannelSpec>& channels() const { return channels_; }  // index = ChannelId
  std::uint64_t message_count() const { return message_count_; }
  std::uint64_t start_ns() const { return start_ns_; }
  std::uint64_t end_ns() const { return end_ns_; }
  // Every message in log-time order (ties: file order).
  Status ForEach(const std::function<void(const McapMessage&)>& fn) const;

 private:
  std::string path_;
  std::vector<ChannelSpec> channels_;
  std::uint64_t message_count_ = 0;
  std::uint64_t start_ns_ = 0;
  std::uint64_t end_ns_ = 0;
};

}  // namespace swarmbox::record
