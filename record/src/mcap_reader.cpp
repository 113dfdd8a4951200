// McapReader: footer -> summary (CRC) -> data section CRC at Open; ForEach merges the chunks by
// log time, decompressing each once. Spec: https://mcap.dev/spec.
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <queue>
#include <tuple>
#include <utility>

#include "detail/bytes.hpp"
#include "detail/mcap_format.hpp"
#include "swarmbox/record/mcap.hpp"

namespace swarmbox::record {

using detail::ByteReader;
using detail::Op;

std::string_view CompressionName(Compression c) {
  switch (c) {
    case Compression::kNone:
      return "none";
    case Compression::kZstd:
      return "zstd";
    case Compression::kLz4:
      return "lz4";
  }
  return "none";
}

Result<Compression> ParseCompression(std::string_view name) {
  for (Compression c : {Compression::kZstd, Compression::kLz4, Compression::kNone}) {
    if (name == CompressionName(c)) return c;
  }
  return Error(ErrorCode::kInvalidArgument,
               "unknown compression \"" + std::string(name) + "\" (expected zstd, lz4 or none)");
}

namespace {

// A read-only file with positioned reads; closes itself.
class File {
 public:
  static Result<File> Open(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (f == nullptr) return Error(ErrorCode::kIo, std::string("cannot open: ") + std::strerror(errno), path);
    File file(f, path);
    if (std::fseek(f, 0, SEEK_END) != 0) return file.IoError("seek failed");
    const long size = std::ftell(f);
    if (size < 0) return file.IoError("cannot tell the size");
    file.size_ = static_cast<std::uint64_t>(size);
    return file;
  }
  File(File&& o) noexcept : f_(std::exchange(o.f_, nullptr)), path_(std::move(o.path_)), size_(o.size_) {}
  File& operator=(File&&) = delete;
  File(const File&) = delete;
  File& operator=(const File&) = delete;
  ~File() {
    if (f_ != nullptr) std::fclose(f_);
  }

  std::uint64_t size() const { return size_; }

  // Exactly `n` bytes at `offset` into *out.
  Status Read(std::uint64_t offset, std::uint64_t n, std::string* out) {
    if (offset > size_ || n > size_ - offset) {
      return Error(ErrorCode::kProtocol,
                   "record at byte " + std::to_string(offset) + " runs past the end of the file", path_);
    }
    out->resize(static_cast<std::size_t>(n));
    if (std::fseek(f_, static_cast<long>(offset), SEEK_SET) != 0) return IoError("seek failed");
    if (n > 0 && std::fread(out->data(), 1, out->size(), f_) != out->size()) return IoError("read failed");
    return Ok{};
  }

  // CRC32 of bytes [0, end), read in blocks.
  Result<std::uint32_t> Crc(std::uint64_t end) {
    std::string block;
    std::uint32_t crc = 0;
    constexpr std::uint64_t kBlock = 1u << 20;
    for (std::uint64_t at = 0; at < end; at += kBlock) {
      SWARMBOX_TRY(Read(at, std::min(kBlock, end - at), &block));
      crc = detail::Crc32(block, crc);
    }
    return crc;
  }

 private:
  File(std::FILE* f, std::string path) : f_(f), path_(std::move(path)) {}
  Error IoError(const char* what) const {
    return Error(ErrorCode::kIo, std::string(what) + ": " + std::strerror(errno), path_);
  }
  std::FILE* f_;
  std::string path_;
  std::uint64_t size_ = 0;
};

Error Malformed(const std::string& path, std::uint64_t offset, const std::string& what) {
  return Error(ErrorCode::kProtocol, what + " (at byte " + std::to_string(offset) + ")", path);
}

struct RawRecord {
  Op op;
  std::string_view content;
  std::uint64_t offset;  // of the opcode, from the start of the file (or of the chunk's records)
};

// Splits `bytes` (which starts at file offset `base`) into records.
Result<std::vector<RawRecord>> SplitRecords(std::string_view bytes, std::uint64_t base, const std::string& path) {
  std::vector<RawRecord> out;
  ByteReader r(bytes);
  while (r.remaining() > 0) {
    const std::uint64_t at = base + r.pos();
    const auto op = static_cast<Op>(r.U8());
    const std::uint64_t length = r.U64();
    std::string_view content = r.Take(length);
    if (!r.ok()) return Malformed(path, at, "truncated record");
    out.push_back({op, content, at});
  }
  return out;
}

// The magic and the Header record: the writer's profile and library.
struct Header {
  std::string profile;
  std::string library;
};

Result<Header> ReadHeader(File& file, const std::string& path) {
  std::string buf;
  SWARMBOX_TRY(file.Read(0, detail::kMagic.size() + detail::kRecordPrefixBytes, &buf));
  if (std::string_view(buf).substr(0, detail::kMagic.size()) != detail::kMagic) {
    return Malformed(path, 0, "not an MCAP file (no MCAP0 magic)");
  }
  ByteReader r(std::string_view(buf).substr(detail::kMagic.size()));
  if (static_cast<Op>(r.U8()) != Op::kHeader) return Malformed(path, 8, "the first record is not a Header");
  const std::uint64_t length = r.U64();
  std::string header;
  SWARMBOX_TRY(file.Read(detail::kMagic.size() + detail::kRecordPrefixBytes, length, &header));
  ByteReader h(header);
  Header out;
  out.profile = std::string(h.Str());
  out.library = std::string(h.Str());
  if (!h.ok()) return Malformed(path, 8, "truncated Header");
  return out;
}

// The Footer record (its bytes and its offsets into the file), followed by the closing magic.
struct Footer {
  std::string bytes;
  std::uint64_t at = 0;
  std::uint64_t summary_start = 0;
  std::uint64_t summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
};

Result<Footer> ReadFooter(File& file, const std::string& path, std::uint64_t min_size) {
  Footer f;
  f.at = file.size() - detail::kMagic.size() - detail::kFooterRecordBytes;
  SWARMBOX_TRY(file.Read(f.at, detail::kFooterRecordBytes + detail::kMagic.size(), &f.bytes));
  if (std::string_view(f.bytes).substr(detail::kFooterRecordBytes) != detail::kMagic ||
      static_cast<Op>(f.bytes[0]) != Op::kFooter) {
    return Malformed(path, f.at,
                     "no Footer and closing magic at the end: the file is truncated (its writer never closed it)");
  }
  ByteReader fr(std::string_view(f.bytes).substr(1));
  const std::uint64_t footer_length = fr.U64();
  f.summary_start = fr.U64();
  f.summary_offset_start = fr.U64();
  f.summary_crc = fr.U32();
  if (footer_length != detail::kFooterContentBytes) return Malformed(path, f.at, "Footer of unexpected length");
  if (f.summary_start == 0) {
    return Malformed(path, f.at, "no summary section: McapReader reads indexed files only");
  }
  if (f.summary_start < min_size - detail::kFooterRecordBytes || f.summary_start > f.at ||
      (f.summary_offset_start != 0 && (f.summary_offset_start < f.summary_start || f.summary_offset_start > f.at))) {
    return Malformed(path, f.at, "Footer offsets outside the file");
  }
  return f;
}

// Summary (and summary offsets), checked against the footer's CRC.
Result<std::string> ReadSummary(File& file, const std::string& path, const Footer& footer) {
  std::string summary;
  SWARMBOX_TRY(file.Read(footer.summary_start, footer.at - footer.summary_start, &summary));
  if (footer.summary_crc != 0) {
    std::uint32_t crc = detail::Crc32(summary);
    crc = detail::Crc32(std::string_view(footer.bytes).substr(0, detail::kRecordPrefixBytes + 16), crc);
    if (crc != footer.summary_crc) {
      return Malformed(path, footer.summary_start, "summary CRC mismatch: the summary section is corrupt");
    }
  }
  return summary;
}

// DataEnd right before the summary, and the data section's CRC; returns where DataEnd starts.
Result<std::uint64_t> CheckDataSection(File& file, const std::string& path, std::uint64_t summary_start) {
  if (summary_start < detail::kDataEndRecordBytes + detail::kMagic.size()) {
    return Malformed(path, summary_start, "no DataEnd record before the summary");
  }
  const std::uint64_t data_end_at = summary_start - detail::kDataEndRecordBytes;
  std::string buf;
  SWARMBOX_TRY(file.Read(data_end_at, detail::kDataEndRecordBytes, &buf));
  ByteReader r(buf);
  const auto op = static_cast<Op>(r.U8());
  const std::uint64_t length = r.U64();
  const std::uint32_t data_crc = r.U32();
  if (op != Op::kDataEnd || length != 4) return Malformed(path, data_end_at, "no DataEnd record before the summary");
  if (data_crc != 0) {
    auto crc = file.Crc(data_end_at);
    if (!crc) return crc.error();
    if (*crc != data_crc) return Malformed(path, 0, "data section CRC mismatch: the data section is corrupt");
  }
  return data_end_at;
}

// What the summary's records say.
struct Summary {
  struct SchemaInfo {
    std::string name;
    std::string data;
  };
  struct ChunkIndex {
    std::uint64_t start_ns = 0;
    std::uint64_t offset = 0;
    std::uint64_t length = 0;
  };
  std::map<std::uint16_t, SchemaInfo> schemas;
  std::map<std::uint16_t, std::pair<std::uint16_t, std::string>> channels;  // id -> (schema, topic)
  bool have_statistics = false;
  std::uint64_t message_count = 0;
  std::uint64_t start_ns = 0;
  std::uint64_t end_ns = 0;
  std::vector<ChunkIndex> chunks;
};

Status DecodeSchema(const RawRecord& rec, const std::string& path, Summary* out) {
  ByteReader r(rec.content);
  const std::uint16_t id = r.U16();
  Summary::SchemaInfo s{std::string(r.Str()), {}};
  r.Str();  // encoding
  s.data = std::string(r.Str());
  if (!r.ok()) return Malformed(path, rec.offset, "truncated Schema record");
  if (id != 0) out->schemas[id] = std::move(s);
  return Ok{};
}

Status DecodeChannel(const RawRecord& rec, const std::string& path, Summary* out) {
  ByteReader r(rec.content);
  const std::uint16_t id = r.U16();
  const std::uint16_t schema = r.U16();
  std::string topic(r.Str());
  r.Str();  // message encoding
  if (!r.ok()) return Malformed(path, rec.offset, "truncated Channel record");
  out->channels[id] = {schema, std::move(topic)};
  return Ok{};
}

Status DecodeStatistics(const RawRecord& rec, const std::string& path, Summary* out) {
  ByteReader r(rec.content);
  out->message_count = r.U64();
  r.U16();  // schema count
  r.U32();  // channel count
  r.U32();  // attachment count
  r.U32();  // metadata count
  r.U32();  // chunk count
  out->start_ns = r.U64();
  out->end_ns = r.U64();
  if (!r.ok()) return Malformed(path, rec.offset, "truncated Statistics record");
  out->have_statistics = true;
  return Ok{};
}

Status DecodeChunkIndex(const RawRecord& rec, const std::string& path, std::uint64_t data_end_at, Summary* out) {
  ByteReader r(rec.content);
  Summary::ChunkIndex c;
  c.start_ns = r.U64();
  r.U64();  // end
  c.offset = r.U64();
  c.length = r.U64();
  if (!r.ok()) return Malformed(path, rec.offset, "truncated ChunkIndex record");
  if (c.offset >= data_end_at || c.length > data_end_at - c.offset) {
    return Malformed(path, rec.offset, "ChunkIndex points outside the data section");
  }
  out->chunks.push_back(c);
  return Ok{};
}

// The summary records up to the summary offsets; other summary records (attachment/metadata
// indexes) are not needed here.
Result<Summary> DecodeSummary(std::string_view records_bytes, std::uint64_t summary_start,
                              std::uint64_t data_end_at, const std::string& path) {
  auto records = SplitRecords(records_bytes, summary_start, path);
  if (!records) return records.error();
  Summary out;
  for (const RawRecord& rec : *records) {
    if (rec.op == Op::kSchema) SWARMBOX_TRY(DecodeSchema(rec, path, &out));
    if (rec.op == Op::kChannel) SWARMBOX_TRY(DecodeChannel(rec, path, &out));
    if (rec.op == Op::kStatistics) SWARMBOX_TRY(DecodeStatistics(rec, path, &out));
    if (rec.op == Op::kChunkIndex) SWARMBOX_TRY(DecodeChunkIndex(rec, path, data_end_at, &out));
  }
  if (!out.have_statistics) return Malformed(path, summary_start, "no Statistics record in the summary");
  if (out.message_count > 0 && out.chunks.empty()) {
    return Malformed(path, summary_start, "messages but no ChunkIndex: McapReader reads chunked files only");
  }
  std::sort(out.chunks.begin(), out.chunks.end(), [](const Summary::ChunkIndex& a, const Summary::ChunkIndex& b) {
    return std::tie(a.start_ns, a.offset) < std::tie(b.start_ns, b.offset);
  });
  return out;
}

// Each channel with its schema, in MCAP channel id order.
Result<std::vector<std::pair<std::uint16_t, ChannelSpec>>> ChannelSpecs(Summary& summary, std::uint64_t summary_start,
                                                                        const std::string& path) {
  std::vector<std::pair<std::uint16_t, ChannelSpec>> out;
  for (auto& [id, channel] : summary.channels) {
    ChannelSpec spec;
    spec.topic = std::move(channel.second);
    if (channel.first != 0) {
      auto it = summary.schemas.find(channel.first);
      if (it == summary.schemas.end()) {
        return Malformed(path, summary_start, "channel " + spec.topic + " names a schema the summary lacks");
      }
      spec.schema_name = it->second.name;
      spec.schema = it->second.data;
    }
    out.emplace_back(id, std::move(spec));
  }
  return out;
}

}  // namespace

Result<McapReader> McapReader::Open(const std::string& path) {
  auto file = File::Open(path);
  if (!file) return file.error();
  const std::uint64_t size = file->size();
  const std::uint64_t min_size = 2 * detail::kMagic.size() + detail::kRecordPrefixBytes + detail::kFooterRecordBytes;
  if (size < min_size) return Malformed(path, 0, "not an MCAP file: " + std::to_string(size) + " bytes");
  auto header = ReadHeader(*file, path);
  if (!header) return header.error();
  auto footer = ReadFooter(*file, path, min_size);
  if (!footer) return footer.error();
  auto summary_bytes = ReadSummary(*file, path, *footer);
  if (!summary_bytes) return summary_bytes.error();
  auto data_end_at = CheckDataSection(*file, path, footer->summary_start);
  if (!data_end_at) return data_end_at.error();
  const std::uint64_t summary_end = footer->summary_offset_start != 0 ? footer->summary_offset_start : footer->at;
  auto summary = DecodeSummary(std::string_view(*summary_bytes).substr(0, summary_end - footer->summary_start),
                               footer->summary_start, *data_end_at, path);
  if (!summary) return summary.error();
  auto channels = ChannelSpecs(*summary, footer->summary_start, path);
  if (!channels) return channels.error();
  McapReader reader;
  reader.path_ = path;
  reader.profile_ = std::move(header->profile);
  reader.library_ = std::move(header->library);
  reader.message_count_ = summary->message_count;
  reader.start_ns_ = summary->start_ns;
  reader.end_ns_ = summary->end_ns;
  for (const Summary::ChunkIndex& c : summary->chunks) reader.chunks_.push_back({c.start_ns, c.offset, c.length});
  for (auto& [id, spec] : *channels) {
    reader.channel_index_[id] = static_cast<ChannelId>(reader.channels_.size());
    reader.channels_.push_back(std::move(spec));
  }
  return reader;
}

namespace {

// A message decoded from a chunk, with where it was (the delivery order's tie-breakers).
struct ChunkMessage {
  std::uint64_t log_time;
  std::uint64_t position;  // of the record in the chunk's records
  McapMessage message;
};

// The Chunk record at `offset` (`length` bytes) decompressed into *records, its CRC checked.
Status ReadChunk(File& file, const std::string& path, std::uint64_t offset, std::uint64_t length, std::string* raw,
                 std::string* records) {
  SWARMBOX_TRY(file.Read(offset, length, raw));
  ByteReader r(*raw);
  const auto op = static_cast<Op>(r.U8());
  r.U64();  // content length
  r.U64();  // message_start_time
  r.U64();  // message_end_time
  const std::uint64_t uncompressed_size = r.U64();
  const std::uint32_t uncompressed_crc = r.U32();
  const std::string_view compression = r.Str();
  const std::string_view compressed = r.Take(r.U64());
  if (op != Op::kChunk || !r.ok()) return Malformed(path, offset, "ChunkIndex does not point at a Chunk");
  if (Status s = detail::Decompress(compression, compressed, uncompressed_size, records); !s) {
    return Malformed(path, offset, s.error().message());
  }
  if (uncompressed_crc != 0 && detail::Crc32(*records) != uncompressed_crc) {
    return Malformed(path, offset, "chunk CRC mismatch: the chunk is corrupt");
  }
  return Ok{};
}

// The Message records of a decompressed chunk (at file offset `offset`), by the channel index.
Result<std::vector<ChunkMessage>> ChunkMessages(const std::string& records, std::uint64_t offset, const std::string& path,
                                                const std::unordered_map<std::uint16_t, ChannelId>& channel_index) {
  auto inner = SplitRecords(records, 0, path);
  if (!inner) return inner.error().Context("in the chunk at byte " + std::to_string(offset));
  std::vector<ChunkMessage> out;
  for (const RawRecord& rec : *inner) {
    if (rec.op != Op::kMessage) continue;  // Schema/Channel copies: the summary has them
    ByteReader m(rec.content);
    const std::uint16_t channel = m.U16();
    m.U32();  // sequence
    const std::uint64_t log_time = m.U64();
    m.U64();  // publish time
    if (!m.ok()) return Malformed(path, offset, "truncated Message record in a chunk");
    auto it = channel_index.find(channel);
    if (it == channel_index.end()) {
      return Malformed(path, offset, "message on channel " + std::to_string(channel) + " the summary lacks");
    }
    out.push_back(ChunkMessage{log_time, rec.offset,
                               McapMessage{it->second, log_time, std::string(rec.content.substr(m.pos()))}});
  }
  return out;
}

// Messages decoded but not yet delivered, smallest (log time, chunk offset, position) first.
class OrderedDelivery {
 public:
  explicit OrderedDelivery(const std::function<void(const McapMessage&)>& fn) : fn_(fn) {}

  void Push(std::uint64_t log_time, std::uint64_t chunk_offset, std::uint64_t position, McapMessage message) {
    pending_.push(Pending{log_time, chunk_offset, position, std::move(message)});
  }
  // Delivers every message that sorts before (time, offset).
  void DeliverBefore(std::uint64_t time, std::uint64_t offset) {
    while (!pending_.empty() &&
           std::tie(pending_.top().log_time, pending_.top().chunk_offset) < std::tie(time, offset)) {
      fn_(pending_.top().message);
      pending_.pop();
    }
  }
  void DeliverAll() {
    while (!pending_.empty()) {
      fn_(pending_.top().message);
      pending_.pop();
    }
  }

 private:
  struct Pending {
    std::uint64_t log_time;
    std::uint64_t chunk_offset;
    std::uint64_t position;
    McapMessage message;
  };
  struct Later {
    bool operator()(const Pending& a, const Pending& b) const {
      return std::tie(a.log_time, a.chunk_offset, a.position) > std::tie(b.log_time, b.chunk_offset, b.position);
    }
  };
  const std::function<void(const McapMessage&)>& fn_;
  std::priority_queue<Pending, std::vector<Pending>, Later> pending_;
};

}  // namespace

Status McapReader::ForEach(const std::function<void(const McapMessage&)>& fn) const {
  auto file = File::Open(path_);
  if (!file) return file.error();
  OrderedDelivery delivery(fn);
  std::string raw;
  std::string records;
  for (const ChunkRef& chunk : chunks_) {
    // Every later chunk starts at or after (start_ns, offset): what sorts before it is final.
    delivery.DeliverBefore(chunk.start_ns, chunk.offset);
    SWARMBOX_TRY(ReadChunk(*file, path_, chunk.offset, chunk.length, &raw, &records));
    auto messages = ChunkMessages(records, chunk.offset, path_, channel_index_);
    if (!messages) return messages.error();
    for (ChunkMessage& m : *messages) delivery.Push(m.log_time, chunk.offset, m.position, std::move(m.message));
  }
  delivery.DeliverAll();
  return Ok{};
}

}  // namespace swarmbox::record
