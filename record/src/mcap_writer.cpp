// McapWriter: the data section as chunks with their message indexes, then the summary (Schema,
// Channel, Statistics and ChunkIndex groups), the summary offsets, the footer and the magic.
//
// File layout written (https://mcap.dev/spec, "Multiple Messages with Chunk Indices"):
//   Magic Header
//   { Schema | Channel }            written straight to the data section when a channel is added
//   { Chunk MessageIndex... }       one MessageIndex per channel with messages in the chunk
//   DataEnd(data_section_crc)
//   Schema... Channel... Statistics ChunkIndex...   (summary, grouped by opcode)
//   SummaryOffset...                               (one per group)
//   Footer(summary_start, summary_offset_start, summary_crc) Magic
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "detail/bytes.hpp"
#include "detail/mcap_format.hpp"
#include "swarmbox/common/version.hpp"
#include "swarmbox/record/mcap.hpp"

namespace swarmbox::record {

using detail::ByteWriter;
using detail::Op;

namespace {

// Starts a record in `buf`; returns where its content length goes (patched by EndRecord).
std::size_t BeginRecord(ByteWriter& w, Op op) {
  w.U8(static_cast<std::uint8_t>(op));
  const std::size_t at = w.size();
  w.U64(0);
  return at;
}
void EndRecord(ByteWriter& w, std::size_t length_at) {
  w.PatchU64(length_at, static_cast<std::uint64_t>(w.size() - length_at - 8));
}

struct ChunkIndexEntry {
  std::uint64_t start_ns = 0;
  std::uint64_t end_ns = 0;
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  std::vector<std::pair<std::uint16_t, std::uint64_t>> index_offsets;
  std::uint64_t index_length = 0;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

}  // namespace

struct McapWriter::Impl {
  std::string path;
  McapOptions options;
  std::FILE* file = nullptr;
  std::mutex mu;  // Sink calls may come from more than one thread: one at a time

  std::uint64_t pos = 0;          // bytes written so far
  std::uint32_t data_crc = 0;     // CRC of everything before DataEnd
  std::uint32_t summary_crc = 0;  // CRC from summary_start on
  bool in_summary = false;
  bool closed = false;
  std::optional<Error> failure;   // the first I/O error: every later call returns it

  struct SchemaEntry {
    std::uint16_t id;
    std::string name;
    std::string text;
  };
  std::vector<SchemaEntry> schemas;  // id = index + 1 (0 means "no schema" in MCAP)
  struct ChannelEntry {
    ChannelSpec spec;
    std::uint16_t schema_id = 0;
    std::uint32_t sequence = 0;
    std::uint64_t count = 0;
  };
  std::vector<ChannelEntry> channels;  // MCAP channel id = ChannelId = index

  // The open chunk.
  std::string records;
  ByteWriter records_writer{&records};
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index;
  std::uint64_t chunk_start_ns = 0;
  std::uint64_t chunk_end_ns = 0;
  std::uint64_t chunk_messages = 0;

  detail::Compressor compressor;
  std::string compressed;  // reused buffer
  std::vector<ChunkIndexEntry> chunk_indexes;

  std::uint64_t message_count = 0;
  std::uint64_t start_ns = 0;
  std::uint64_t end_ns = 0;

  Status Fail(Error e) {
    if (!failure) failure = std::move(e);
    return *failure;
  }

  Status Out(std::string_view bytes) {
    if (failure) return *failure;
    if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file) != bytes.size()) {
      return Fail(Error(ErrorCode::kIo, std::string("write failed: ") + std::strerror(errno), path));
    }
    pos += bytes.size();
    if (in_summary) {
      summary_crc = detail::Crc32(bytes, summary_crc);
    } else {
      data_crc = detail::Crc32(bytes, data_crc);
    }
    return Ok{};
  }

  static void SchemaRecord(ByteWriter& w, const SchemaEntry& s) {
    const std::size_t at = BeginRecord(w, Op::kSchema);
    w.U16(s.id);
    w.Str(s.name);
    w.Str(s.text.empty() ? "" : "jsonschema");  // no schema text: encoding "" (MCAP registry)
    w.Str(s.text);
    EndRecord(w, at);
  }

  static void ChannelRecord(ByteWriter& w, std::uint16_t id, const ChannelEntry& c) {
    const std::size_t at = BeginRecord(w, Op::kChannel);
    w.U16(id);
    w.U16(c.schema_id);
    w.Str(c.spec.topic);
    w.Str("json");
    w.U32(0);  // metadata: an empty Map<string, string>
    EndRecord(w, at);
  }

  // The Chunk record's opening (everything before the compressed records).
  std::string ChunkHead(std::string_view compression) const {
    std::string head;
    ByteWriter w(&head);
    w.U8(static_cast<std::uint8_t>(Op::kChunk));
    w.U64(8 + 8 + 8 + 4 + 4 + compression.size() + 8 + compressed.size());
    w.U64(chunk_start_ns);
    w.U64(chunk_end_ns);
    w.U64(records.size());
    w.U32(detail::Crc32(records));
    w.Str(compression);
    w.U64(compressed.size());
    return head;
  }

  // One MessageIndex per channel, entries in log-time order (file order among equal times); their
  // offsets (the file starts them at `at`) into entry.
  std::string MessageIndexes(std::uint64_t at, ChunkIndexEntry* entry) {
    std::string index;
    ByteWriter iw(&index);
    for (auto& [channel, entries] : chunk_index) {
      std::stable_sort(entries.begin(), entries.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      entry->index_offsets.emplace_back(channel, at + index.size());
      const std::size_t start = BeginRecord(iw, Op::kMessageIndex);
      iw.U16(channel);
      iw.U32(static_cast<std::uint32_t>(entries.size() * 16));
      for (const auto& [time, offset] : entries) {
        iw.U64(time);
        iw.U64(offset);
      }
      EndRecord(iw, start);
    }
    return index;
  }

  Status FlushChunk() {
    if (records.empty()) return Ok{};
    SWARMBOX_TRY(compressor.Compress(options.compression, records, &compressed));
    ChunkIndexEntry entry;
    entry.start_ns = chunk_start_ns;
    entry.end_ns = chunk_end_ns;
    entry.offset = pos;
    entry.compressed_size = compressed.size();
    entry.uncompressed_size = records.size();
    SWARMBOX_TRY(Out(ChunkHead(detail::CompressionField(options.compression))));
    SWARMBOX_TRY(Out(compressed));
    entry.length = pos - entry.offset;
    const std::string index = MessageIndexes(pos, &entry);
    entry.index_length = index.size();
    SWARMBOX_TRY(Out(index));
    chunk_indexes.push_back(std::move(entry));

    records.clear();
    chunk_index.clear();
    chunk_messages = 0;
    return Ok{};
  }

  Status WriteDataEnd() {
    std::string tail;
    ByteWriter w(&tail);
    const std::size_t at = BeginRecord(w, Op::kDataEnd);
    w.U32(data_crc);
    EndRecord(w, at);
    return Out(tail);
  }

  void StatisticsRecord(ByteWriter& sw) const {
    const std::size_t s = BeginRecord(sw, Op::kStatistics);
    sw.U64(message_count);
    sw.U16(static_cast<std::uint16_t>(schemas.size()));
    sw.U32(static_cast<std::uint32_t>(channels.size()));
    sw.U32(0);  // attachments
    sw.U32(0);  // metadata
    sw.U32(static_cast<std::uint32_t>(chunk_indexes.size()));
    sw.U64(start_ns);
    sw.U64(end_ns);
    sw.U32(static_cast<std::uint32_t>(channels.size() * (2 + 8)));
    for (std::size_t i = 0; i < channels.size(); ++i) {
      sw.U16(static_cast<std::uint16_t>(i));
      sw.U64(channels[i].count);
    }
    EndRecord(sw, s);
  }

  void ChunkIndexRecords(ByteWriter& sw) const {
    for (const ChunkIndexEntry& c : chunk_indexes) {
      const std::size_t s = BeginRecord(sw, Op::kChunkIndex);
      sw.U64(c.start_ns);
      sw.U64(c.end_ns);
      sw.U64(c.offset);
      sw.U64(c.length);
      sw.U32(static_cast<std::uint32_t>(c.index_offsets.size() * (2 + 8)));
      for (const auto& [channel, offset] : c.index_offsets) {
        sw.U16(channel);
        sw.U64(offset);
      }
      sw.U64(c.index_length);
      sw.Str(detail::CompressionField(options.compression));
      sw.U64(c.compressed_size);
      sw.U64(c.uncompressed_size);
      EndRecord(sw, s);
    }
  }

  // A SummaryOffset per group (opcode, start, length), then the footer up to its summary_crc
  // (the summary CRC covers the summary, the offsets and the footer up to summary_crc).
  static void SummaryOffsetsAndFooterHead(ByteWriter& sw,
                                          const std::vector<std::tuple<Op, std::uint64_t, std::uint64_t>>& groups,
                                          std::uint64_t summary_start, std::uint64_t summary_offset_start) {
    for (const auto& [op, start, length] : groups) {
      const std::size_t s = BeginRecord(sw, Op::kSummaryOffset);
      sw.U8(static_cast<std::uint8_t>(op));
      sw.U64(start);
      sw.U64(length);
      EndRecord(sw, s);
    }
    sw.U8(static_cast<std::uint8_t>(Op::kFooter));
    sw.U64(detail::kFooterContentBytes);
    sw.U64(summary_start);
    sw.U64(summary_offset_start);
  }

  Status WriteSummaryAndFooter() {
    SWARMBOX_TRY(FlushChunk());
    SWARMBOX_TRY(WriteDataEnd());
    // Summary: one group per opcode, remembered for the SummaryOffset records.
    in_summary = true;
    const std::uint64_t summary_start = pos;
    std::string summary;
    ByteWriter sw(&summary);
    std::vector<std::tuple<Op, std::uint64_t, std::uint64_t>> groups;
    auto group = [&](Op op, auto&& body) {
      const std::size_t begin = summary.size();
      body();
      if (summary.size() > begin) groups.emplace_back(op, summary_start + begin, summary.size() - begin);
    };
    group(Op::kSchema, [&] {
      for (const SchemaEntry& s : schemas) SchemaRecord(sw, s);
    });
    group(Op::kChannel, [&] {
      for (std::size_t i = 0; i < channels.size(); ++i) {
        ChannelRecord(sw, static_cast<std::uint16_t>(i), channels[i]);
      }
    });
    group(Op::kStatistics, [&] { StatisticsRecord(sw); });
    group(Op::kChunkIndex, [&] { ChunkIndexRecords(sw); });
    SummaryOffsetsAndFooterHead(sw, groups, summary_start, summary_start + summary.size());
    SWARMBOX_TRY(Out(summary));
    std::string end;
    ByteWriter ew(&end);
    ew.U32(summary_crc);
    ew.Raw(detail::kMagic);
    return Out(end);
  }

  Status Close() {
    if (closed) return failure ? Status(*failure) : Status(Ok{});
    closed = true;
    Status written = failure ? Status(*failure) : WriteSummaryAndFooter();
    const bool close_failed = std::fclose(file) != 0;
    file = nullptr;
    if (!written) return written;
    if (close_failed) {
      return Fail(Error(ErrorCode::kIo, std::string("closing failed: ") + std::strerror(errno), path));
    }
    return Ok{};
  }
};

McapWriter::McapWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

McapWriter::~McapWriter() {
  if (!impl_) return;
  if (Status s = Close(); !s) {
    std::fprintf(stderr, "swarmbox: closing the recording failed: %s\n", s.error().ToString().c_str());
  }
}

Result<std::unique_ptr<McapWriter>> McapWriter::Create(const std::string& path, McapOptions options) {
  if (options.chunk_bytes == 0) return Error(ErrorCode::kInvalidArgument, "chunk_bytes must be > 0", path);
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) {
    return Error(ErrorCode::kIo, std::string("cannot create: ") + std::strerror(errno), path);
  }
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->options = std::move(options);
  impl->file = file;
  impl->records.reserve(std::min<std::size_t>(impl->options.chunk_bytes, 64u << 20) + (64u << 10));

  std::string head;
  ByteWriter w(&head);
  w.Raw(detail::kMagic);
  const std::size_t at = BeginRecord(w, Op::kHeader);
  w.Str(impl->options.profile);
  w.Str("swarmbox " + std::string(Build().version));
  EndRecord(w, at);
  if (Status s = impl->Out(head); !s) {
    std::fclose(file);
    impl->file = nullptr;
    impl->closed = true;
    return s.error();
  }
  return std::unique_ptr<McapWriter>(new McapWriter(std::move(impl)));
}

Result<ChannelId> McapWriter::AddChannel(const ChannelSpec& spec) {
  Impl& m = *impl_;
  std::lock_guard lock(m.mu);
  if (m.closed) return Error(ErrorCode::kInvalidArgument, "AddChannel after Close", m.path);
  if (m.failure) return *m.failure;
  for (std::size_t i = 0; i < m.channels.size(); ++i) {
    const ChannelSpec& c = m.channels[i].spec;
    if (c.topic == spec.topic && c.schema_name == spec.schema_name && c.schema == spec.schema) {
      return static_cast<ChannelId>(i);  // the same channel again: the same id
    }
  }
  if (m.channels.size() > std::numeric_limits<std::uint16_t>::max()) {
    return Error(ErrorCode::kInvalidArgument, "more than 65536 channels (MCAP channel ids are uint16)", m.path);
  }
  std::string out;
  ByteWriter w(&out);
  std::uint16_t schema_id = 0;
  if (!spec.schema_name.empty() || !spec.schema.empty()) {
    for (const auto& s : m.schemas) {
      if (s.name == spec.schema_name && s.text == spec.schema) schema_id = s.id;
    }
    if (schema_id == 0) {
      if (m.schemas.size() >= std::numeric_limits<std::uint16_t>::max()) {
        return Error(ErrorCode::kInvalidArgument, "more than 65535 schemas", m.path);
      }
      schema_id = static_cast<std::uint16_t>(m.schemas.size() + 1);
      m.schemas.push_back({schema_id, spec.schema_name, spec.schema});
      Impl::SchemaRecord(w, m.schemas.back());
    }
  }
  Impl::ChannelEntry entry;
  entry.spec = spec;
  entry.schema_id = schema_id;
  const auto id = static_cast<std::uint16_t>(m.channels.size());
  Impl::ChannelRecord(w, id, entry);
  SWARMBOX_TRY(m.Out(out));
  m.channels.push_back(std::move(entry));
  return ChannelId{id};
}

Status McapWriter::Write(ChannelId channel, std::uint64_t log_time_ns, std::string_view json) {
  Impl& m = *impl_;
  std::lock_guard lock(m.mu);
  if (m.closed) return Error(ErrorCode::kInvalidArgument, "Write after Close", m.path);
  if (m.failure) return *m.failure;
  if (channel >= m.channels.size()) {
    return Error(ErrorCode::kInvalidArgument, "Write on unknown channel " + std::to_string(channel), m.path);
  }
  Impl::ChannelEntry& c = m.channels[channel];
  const auto id = static_cast<std::uint16_t>(channel);
  const std::uint64_t offset = m.records.size();
  ByteWriter& w = m.records_writer;
  w.U8(static_cast<std::uint8_t>(Op::kMessage));
  w.U64(2 + 4 + 8 + 8 + json.size());
  w.U16(id);
  w.U32(c.sequence++);
  w.U64(log_time_ns);
  w.U64(log_time_ns);  // publish_time: no other time is known
  w.Raw(json);
  m.chunk_index[id].emplace_back(log_time_ns, offset);

  if (m.chunk_messages == 0 || log_time_ns < m.chunk_start_ns) m.chunk_start_ns = log_time_ns;
  if (m.chunk_messages == 0 || log_time_ns > m.chunk_end_ns) m.chunk_end_ns = log_time_ns;
  if (m.message_count == 0 || log_time_ns < m.start_ns) m.start_ns = log_time_ns;
  if (m.message_count == 0 || log_time_ns > m.end_ns) m.end_ns = log_time_ns;
  ++m.chunk_messages;
  ++m.message_count;
  ++c.count;
  if (m.records.size() >= m.options.chunk_bytes) return m.FlushChunk();
  return Ok{};
}

Status McapWriter::Close() {
  std::lock_guard lock(impl_->mu);
  return impl_->Close();
}

}  // namespace swarmbox::record
