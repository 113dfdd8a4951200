#include "swarmbox/raft/wal_storage.hpp"

#include <zlib.h>

#include "swarmbox/raft/detail/byte_io.hpp"

namespace swarmbox::raft {

namespace {

enum RecordKind : std::uint8_t { kHardStateRecord = 1, kEntryRecord = 2, kBaseRecord = 3 };

std::uint32_t Crc32(std::span<const std::uint8_t> bytes) {
  uLong crc = crc32(0L, Z_NULL, 0);
  // zlib takes uInt lengths: feed large buffers in pieces.
  std::size_t done = 0;
  while (done < bytes.size()) {
    const std::size_t n = std::min<std::size_t>(bytes.size() - done, 1u << 30);
    crc = crc32(crc, bytes.data() + done, static_cast<uInt>(n));
    done += n;
  }
  return static_cast<std::uint32_t>(crc);
}

// Frames one payload: length | crc | payload.
void AppendRecord(Bytes* out, const Bytes& payload) {
  detail::ByteWriter w(out);
  w.Fixed32(static_cast<std::uint32_t>(payload.size()));
  w.Fixed32(Crc32(payload));
  out->insert(out->end(), payload.begin(), payload.end());
}

// One record's payload: its kind byte, then the fields `write_fields(w)` writes.
template <typename WriteFields>
Bytes RecordPayload(std::uint8_t kind, WriteFields write_fields) {
  Bytes p;
  detail::ByteWriter w(&p);
  w.U8(kind);
  write_fields(w);
  return p;
}

Bytes HardStatePayload(const HardState& hs) {
  return RecordPayload(kHardStateRecord, [&](detail::ByteWriter& w) {
    w.Varint(hs.term);
    w.Varint(hs.vote);
    w.Varint(hs.commit);
  });
}

Bytes EntryPayload(const Entry& e) {
  return RecordPayload(kEntryRecord, [&](detail::ByteWriter& w) {
    w.Varint(e.term);
    w.Varint(e.index);
    w.U8(static_cast<std::uint8_t>(e.type));
    w.Blob(e.data);
  });
}

Bytes BasePayload(std::uint64_t index, std::uint64_t term) {
  return RecordPayload(kBaseRecord, [&](detail::ByteWriter& w) {
    w.Varint(index);
    w.Varint(term);
  });
}

Bytes SnapshotFile(const Snapshot& s) {
  Bytes p;
  detail::ByteWriter w(&p);
  w.Varint(s.index);
  w.Varint(s.term);
  w.Blob(s.data);
  detail::WriteConfState(w, s.conf);
  Bytes out;
  AppendRecord(&out, p);
  return out;
}

// Appends an entry to a log being rebuilt, truncating any suffix it replaces.
bool PutEntry(PersistentState* st, Entry e) {
  const std::uint64_t base = st->snapshot.index;
  const std::uint64_t last = base + st->entries.size();
  if (e.index <= base || e.index > last + 1) return false;
  st->entries.resize(static_cast<std::size_t>(e.index - base - 1));
  st->entries.push_back(std::move(e));
  return true;
}

// The snapshot file: one framed record (written atomically: any damage is corruption).
Result<Snapshot> ParseSnapshotFile(const Bytes& bytes, const std::string& path) {
  detail::ByteReader r(bytes);
  const std::uint32_t len = r.Fixed32();
  const std::uint32_t crc = r.Fixed32();
  if (!r.ok() || len != r.remaining()) {
    return Error(ErrorCode::kProtocol, "corrupt snapshot file (bad length)", path);
  }
  std::span<const std::uint8_t> payload(bytes.data() + 8, len);
  if (Crc32(payload) != crc) {
    return Error(ErrorCode::kProtocol, "corrupt snapshot file (crc mismatch)", path);
  }
  detail::ByteReader p(payload);
  Snapshot snapshot;
  snapshot.index = p.Varint();
  snapshot.term = p.Varint();
  snapshot.data = p.Blob();
  // The membership at the snapshot; absent in files written before membership changes.
  if (p.ok() && !p.at_end()) detail::ReadConfState(p, &snapshot.conf);
  if (!p.ok() || !p.at_end() || snapshot.index == 0) {
    return Error(ErrorCode::kProtocol, "corrupt snapshot file: " + p.error(), path);
  }
  return snapshot;
}

// The payload of the WAL record framed at `pos`, or nullopt when the rest of the file is a write
// torn by a crash (too short, or a bad crc on the last record); a damaged record followed by more
// records is corruption.
using Frame = std::optional<std::span<const std::uint8_t>>;  // nullopt: a torn write
Result<Frame> ReadFrame(const Bytes& data, std::size_t pos, const std::string& path) {
  const std::size_t left = data.size() - pos;
  if (left < 8) return Frame{};
  detail::ByteReader h(std::span<const std::uint8_t>(data.data() + pos, 8));
  const std::uint32_t len = h.Fixed32();
  const std::uint32_t crc = h.Fixed32();
  if (len > WalStorage::kMaxRecordBytes) {
    return Error(ErrorCode::kProtocol,
                 "corrupt record at byte " + std::to_string(pos) + " (length " +
                     std::to_string(len) + ")",
                 path);
  }
  if (len > left - 8) return Frame{};
  std::span<const std::uint8_t> payload(data.data() + pos + 8, len);
  if (Crc32(payload) != crc) {
    if (pos + 8 + len == data.size()) return Frame{};
    return Error(ErrorCode::kProtocol,
                 "corrupt record at byte " + std::to_string(pos) +
                     " (crc mismatch) followed by more records: not a torn write",
                 path);
  }
  return Frame(payload);
}

// Replays one record of kind `kind` (already read from `p`) into the log being rebuilt; false
// when the record is invalid there (a bad entry type, a gap, a base record that is not first).
bool ReplayRecord(detail::ByteReader& p, std::uint8_t kind, std::size_t record,
                  PersistentState* st) {
  if (kind == kHardStateRecord) {
    st->hard_state.term = p.Varint();
    st->hard_state.vote = p.Varint();
    st->hard_state.commit = p.Varint();
    return true;
  }
  if (kind == kEntryRecord) {
    Entry e;
    e.term = p.Varint();
    e.index = p.Varint();
    const std::uint8_t t = p.U8();
    e.type = static_cast<EntryType>(t <= kMaxEntryType ? t : 0);
    e.data = p.Blob();
    return t <= kMaxEntryType && p.ok() && PutEntry(st, std::move(e));
  }
  if (kind == kBaseRecord) {
    st->snapshot.index = p.Varint();
    st->snapshot.term = p.Varint();
    return record == 0;
  }
  return false;
}

// Drops the rebuilt log's entries up to the snapshot file's index; keeps the ones after it only
// when the entry at the snapshot's index has the snapshot's term.
void TrimToSnapshot(const Snapshot& file_snapshot, PersistentState* st) {
  if (file_snapshot.index <= st->snapshot.index) return;
  const std::uint64_t base = st->snapshot.index;
  const std::uint64_t last = base + st->entries.size();
  std::vector<Entry> rest;
  if (file_snapshot.index < last &&
      st->entries[file_snapshot.index - base - 1].term == file_snapshot.term) {
    rest.assign(st->entries.begin() + static_cast<std::ptrdiff_t>(file_snapshot.index - base),
                st->entries.end());
  }
  st->entries = std::move(rest);
}

}  // namespace

WalStorage::WalStorage(FileSystem& fs, std::string dir)
    : fs_(fs), dir_(std::move(dir)), wal_path_(dir_ + "/wal"), snapshot_path_(dir_ + "/snapshot") {}

Result<std::unique_ptr<WalStorage>> WalStorage::Open(FileSystem& fs, std::string dir) {
  std::unique_ptr<WalStorage> w(new WalStorage(fs, std::move(dir)));
  if (auto s = fs.CreateDirs(w->dir_); !s) return s.error().Context("opening raft storage");
  if (auto s = w->Recover(); !s) return s.error();
  auto f = fs.OpenAppend(w->wal_path_);
  if (!f) return f.error().Context("opening raft wal");
  w->wal_ = std::move(*f);
  return w;
}

// Recover reads the segments (the snapshot file, then the WAL), checks them, and replays the WAL
// onto the snapshot: read, replay, reconcile.
Status WalStorage::Recover() {
  // 1. The snapshot file.
  auto snap_bytes = fs_.ReadFile(snapshot_path_);
  if (!snap_bytes && snap_bytes.error().code() != ErrorCode::kNotFound) return snap_bytes.error();
  Snapshot file_snapshot;
  if (snap_bytes) {
    auto parsed = ParseSnapshotFile(*snap_bytes, snapshot_path_);
    if (!parsed) return parsed.error();
    file_snapshot = std::move(*parsed);
  }
  // 2. The WAL: rebuild the log from its base (an older snapshot, possibly).
  auto wal_bytes = fs_.ReadFile(wal_path_);
  if (!wal_bytes && wal_bytes.error().code() != ErrorCode::kNotFound) return wal_bytes.error();
  const Bytes data = wal_bytes ? std::move(*wal_bytes) : Bytes{};
  PersistentState st;
  if (auto s = ReplayWal(data, &st); !s) return s;
  // 3. Reconcile the two.
  if (auto s = Reconcile(file_snapshot, &st); !s) return s;
  state_ = std::move(st);
  return Ok{};
}

Status WalStorage::ReplayWal(const Bytes& data, PersistentState* st) {
  std::size_t pos = 0;
  std::size_t record = 0;
  while (pos < data.size()) {
    auto payload = ReadFrame(data, pos, wal_path_);
    if (!payload) return payload.error();
    if (!*payload) {
      // A damaged last record is a write torn by a crash: cut it off (see the header).
      torn_bytes_dropped_ = data.size() - pos;
      return fs_.Truncate(wal_path_, pos);
    }
    detail::ByteReader p(**payload);
    const std::uint8_t kind = p.U8();
    const bool good = ReplayRecord(p, kind, record, st);
    if (!good || !p.ok() || !p.at_end()) {
      return Error(ErrorCode::kProtocol,
                   "invalid record " + std::to_string(record) + " (kind " + std::to_string(kind) +
                       ") at byte " + std::to_string(pos) + (p.ok() ? "" : ": " + p.error()),
                   wal_path_);
    }
    pos += 8 + (*payload)->size();
    ++record;
  }
  return Ok{};
}

Status WalStorage::Reconcile(const Snapshot& file_snapshot, PersistentState* st) const {
  // The snapshot file is written before the WAL is rewritten, so its index is at least the
  // WAL's base.
  if (st->snapshot.index > file_snapshot.index) {
    return Error(ErrorCode::kProtocol,
                 "wal starts after snapshot " + std::to_string(st->snapshot.index) +
                     " but the snapshot file holds " + std::to_string(file_snapshot.index),
                 wal_path_);
  }
  TrimToSnapshot(file_snapshot, st);
  st->snapshot = file_snapshot;
  // Save() writes a Ready's entries before its hard state. A write torn between them leaves
  // entries of a term the stored hard state has not reached: we saw that term, but cast no vote
  // in it that anyone heard of (messages go out only after the fsync), so take the term with no
  // vote.
  const std::uint64_t last_term = st->entries.empty() ? st->snapshot.term : st->entries.back().term;
  if (last_term > st->hard_state.term) {
    st->hard_state.term = last_term;
    st->hard_state.vote = kNoNode;
  }
  const std::uint64_t last = st->snapshot.index + st->entries.size();
  if (st->hard_state.commit < st->snapshot.index) st->hard_state.commit = st->snapshot.index;
  if (st->hard_state.commit > last) {
    return Error(ErrorCode::kProtocol,
                 "hard state commit " + std::to_string(st->hard_state.commit) +
                     " beyond the last stored entry " + std::to_string(last),
                 wal_path_);
  }
  return Ok{};
}

Status WalStorage::Fail(Error e) {
  failed_ = e;
  return e;
}

Result<PersistentState> WalStorage::Load() {
  if (failed_) return *failed_;
  return state_;
}

Status WalStorage::Save(const std::optional<HardState>& hard_state, std::span<const Entry> entries,
                        const Snapshot& snapshot) {
  if (failed_) return *failed_;
  if (!snapshot.empty()) {
    // Replace the whole log by the leader's snapshot: snapshot file first, then a fresh WAL.
    if (auto s = fs_.WriteFileAtomic(snapshot_path_, SnapshotFile(snapshot)); !s) {
      return Fail(s.error().Context("saving raft snapshot"));
    }
    state_.snapshot = snapshot;
    state_.entries.clear();
    if (state_.hard_state.commit < snapshot.index) state_.hard_state.commit = snapshot.index;
    if (auto s = RewriteWal(); !s) return s;
  }
  if (entries.empty() && !hard_state) return Ok{};
  Bytes buf;
  for (const Entry& e : entries) {
    AppendRecord(&buf, EntryPayload(e));
    if (!PutEntry(&state_, e)) {
      return Fail(Error(ErrorCode::kInternal,
                        "entry " + std::to_string(e.index) + " does not follow the stored log",
                        wal_path_));
    }
  }
  if (hard_state) {
    AppendRecord(&buf, HardStatePayload(*hard_state));
    state_.hard_state = *hard_state;
  }
  if (auto s = wal_->Append(buf); !s) return Fail(s.error().Context("appending to raft wal"));
  if (auto s = wal_->Sync(); !s) return Fail(s.error().Context("syncing raft wal"));
  return Ok{};
}

Status WalStorage::Compact(const Snapshot& snapshot) {
  if (failed_) return *failed_;
  const std::uint64_t base = state_.snapshot.index;
  const std::uint64_t last = base + state_.entries.size();
  if (snapshot.index <= base || snapshot.index > last) {
    return Error(ErrorCode::kInvalidArgument,
                 "compact to " + std::to_string(snapshot.index) + " outside the stored log (" +
                     std::to_string(base) + ", " + std::to_string(last) + "]",
                 wal_path_);
  }
  if (auto s = fs_.WriteFileAtomic(snapshot_path_, SnapshotFile(snapshot)); !s) {
    return Fail(s.error().Context("saving raft snapshot"));
  }
  state_.entries.erase(state_.entries.begin(),
                       state_.entries.begin() + static_cast<std::ptrdiff_t>(snapshot.index - base));
  state_.snapshot = snapshot;
  return RewriteWal();
}

Status WalStorage::RewriteWal() {
  Bytes buf;
  AppendRecord(&buf, BasePayload(state_.snapshot.index, state_.snapshot.term));
  for (const Entry& e : state_.entries) AppendRecord(&buf, EntryPayload(e));
  AppendRecord(&buf, HardStatePayload(state_.hard_state));
  wal_.reset();
  if (auto s = fs_.WriteFileAtomic(wal_path_, buf); !s) {
    return Fail(s.error().Context("rewriting raft wal"));
  }
  auto f = fs_.OpenAppend(wal_path_);
  if (!f) return Fail(f.error().Context("reopening raft wal"));
  wal_ = std::move(*f);
  return Ok{};
}

}  // namespace swarmbox::raft
