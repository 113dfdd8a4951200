#include "swarmbox/raft/message_codec.hpp"

#include "swarmbox/raft/detail/byte_io.hpp"

namespace swarmbox::raft {

std::uint32_t ClusterTag(const std::vector<std::string>& sorted_names) {
  std::uint32_t h = 2166136261u;
  for (const std::string& name : sorted_names) {
    for (char c : name) {
      h ^= static_cast<std::uint8_t>(c);
      h *= 16777619u;
    }
    h *= 16777619u;  // the 0 separator byte: h ^= 0 is a no-op
  }
  return h;
}

Bytes EncodeMessage(const Message& m, std::uint32_t cluster_tag) {
  SWARMBOX_CHECK(!IsLocalMessage(m.type));
  Bytes out;
  out.reserve(32 + m.entries.size() * 16 + m.snapshot.data.size());
  detail::ByteWriter w(&out);
  w.U8(kWireVersion);
  w.Fixed32(cluster_tag);
  w.U8(static_cast<std::uint8_t>(m.type));
  w.Varint(m.from);
  w.Varint(m.to);
  w.Varint(m.term);
  w.Varint(m.log_term);
  w.Varint(m.index);
  w.Varint(m.commit);
  w.U8(m.reject ? 1 : 0);
  w.Varint(m.reject_hint);
  w.Varint(m.entries.size());
  for (const Entry& e : m.entries) {
    w.Varint(e.term);
    w.Varint(e.index);
    w.U8(static_cast<std::uint8_t>(e.type));
    w.Blob(e.data);
  }
  if (m.type == MessageType::kSnap) {
    w.Varint(m.snapshot.index);
    w.Varint(m.snapshot.term);
    w.Blob(m.snapshot.data);
    detail::WriteConfState(w, m.snapshot.conf);
  }
  return out;
}

namespace {

Error Protocol(std::string what) {
  return Error(ErrorCode::kProtocol, std::move(what), "raft message");
}


// The wire version and the cluster tag before the fields; non-empty: why the message is refused.
std::string ReadHeader(detail::ByteReader& r, std::uint32_t cluster_tag) {
  const std::uint8_t version = r.U8();
  if (!r.ok()) return "empty message";
  if (version != kWireVersion) {
    return "unsupported wire version " + std::to_string(version) + " (expected " +
           std::to_string(kWireVersion) + ")";
  }
  const std::uint32_t tag = r.Fixed32();
  if (r.ok() && tag != cluster_tag) {
    return "message from another cluster (tag " + std::to_string(tag) + ", ours " +
           std::to_string(cluster_tag) + "): member lists differ";
  }
  return {};
}

// The entries of a message; a non-empty result is why they are invalid (an unknown entry type).
std::string ReadEntries(detail::ByteReader& r, std::vector<Entry>* entries) {
  const std::uint64_t n = r.Count(4, "entry");
  entries->reserve(static_cast<std::size_t>(n));
  for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
    Entry e;
    e.term = r.Varint();
    e.index = r.Varint();
    const std::uint8_t et = r.U8();
    if (r.ok() && et > kMaxEntryType) return "invalid entry type " + std::to_string(et);
    e.type = static_cast<EntryType>(et);
    e.data = r.Blob();
    entries->push_back(std::move(e));
  }
  return {};
}

// A kSnap message's snapshot; non-empty: why it is invalid.
std::string ReadSnapshot(detail::ByteReader& r, Snapshot* snapshot) {
  snapshot->index = r.Varint();
  snapshot->term = r.Varint();
  snapshot->data = r.Blob();
  if (r.ok() && (snapshot->index == 0 || snapshot->term == 0)) {
    return "snapshot message without a snapshot";
  }
  detail::ReadConfState(r, &snapshot->conf);
  return {};
}

// What a well-formed message must also be: a sender, a term (but proposals), entries only in
// proposals and appends, an append's entries contiguous after `index` and within `term`.
// Non-empty: why the message is invalid.
std::string CheckMessageFields(const Message& m) {
  if (m.from == kNoNode) return "message without a sender";
  if (m.type != MessageType::kProp && m.term == 0) return "message without a term";
  if (m.type == MessageType::kApp) {
    // The receiver appends these as they are: they must follow `index` and not outrun `term`.
    std::uint64_t prev_term = m.log_term;
    for (std::size_t k = 0; k < m.entries.size(); ++k) {
      const Entry& e = m.entries[k];
      if (e.index != m.index + 1 + k || e.term < prev_term || e.term > m.term) {
        return "append entries are not contiguous (entry " + std::to_string(k) + ")";
      }
      prev_term = e.term;
    }
    if (m.log_term > m.term) return "append log_term beyond the message term";
  } else if (m.type != MessageType::kProp && !m.entries.empty()) {
    return "entries in a " + std::string(MessageTypeName(m.type)) + " message";
  }
  return {};
}

}  // namespace

Result<Message> DecodeMessage(std::span<const std::uint8_t> bytes, std::uint32_t cluster_tag) {
  detail::ByteReader r(bytes);
  if (std::string why = ReadHeader(r, cluster_tag); !why.empty()) return Protocol(std::move(why));
  Message m;
  const std::uint8_t type = r.U8();
  if (r.ok() && (type > kMaxMessageType || IsLocalMessage(static_cast<MessageType>(type)))) {
    return Protocol("invalid message type " + std::to_string(type));
  }
  m.type = static_cast<MessageType>(type);
  m.from = r.Varint();
  m.to = r.Varint();
  m.term = r.Varint();
  m.log_term = r.Varint();
  m.index = r.Varint();
  m.commit = r.Varint();
  const std::uint8_t flags = r.U8();
  if (r.ok() && flags > 1) return Protocol("invalid flags " + std::to_string(flags));
  m.reject = flags == 1;
  m.reject_hint = r.Varint();
  if (std::string why = ReadEntries(r, &m.entries); !why.empty()) return Protocol(std::move(why));
  if (m.type == MessageType::kSnap) {
    if (std::string why = ReadSnapshot(r, &m.snapshot); !why.empty()) return Protocol(std::move(why));
  }
  if (!r.ok()) return Protocol(r.error());
  if (!r.at_end()) {
    return Protocol(std::to_string(r.remaining()) + " trailing bytes at byte " +
                    std::to_string(r.offset()));
  }
  if (std::string why = CheckMessageFields(m); !why.empty()) return Protocol(std::move(why));
  return m;
}

}  // namespace swarmbox::raft
