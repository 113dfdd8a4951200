// WalStorage: the real Storage, a write-ahead log file plus a snapshot file in one directory
// (inside the agent's container: a volume or the container's own filesystem).
//
//   auto wal = WalStorage::Open(fs, "/var/lib/swarmbox/raft");   // reads and checks both files
//   if (!wal) return wal.error();          // "…/wal: corrupt record at byte 4096 (crc mismatch)…"
//   NodeDriver::Open(cfg, **wal, transport, clock, sink);
//
// Files:
//   <dir>/wal       records: fixed32 length | fixed32 crc32(payload) | payload, where payload is
//                   u8 kind + fields: 1 hard state (term, vote, commit), 2 entry (term, index,
//                   type 0 normal / 1 no-op / 2 conf change, data), 3 base (snapshot index, term: first record of a rewritten file).
//                   An entry record for index i replaces any stored entry >= i (Raft §5.3).
//   <dir>/snapshot  one record of the same framing: index, term, state machine data, then the
//                   membership (ConfState: voter count, voters, learner count, learners; absent
//                   in files written before membership changes existed). Written
//                   atomically (tmp + fsync + rename + fsync dir).
// Save() appends every record of a Ready in one write and fsyncs once. Compact() writes the
// snapshot file, then rewrites the WAL as base + hard state + the entries after the snapshot.
//
// Reload: a damaged *last* record (short header, short payload or crc mismatch at the end of the
// file) is a torn write from a crash before its fsync returned: it is cut off (truncated) and the
// node continues with what was acknowledged. A bad record followed by more data is corruption:
// Open fails with kProtocol and the byte offset. (Entries are written before the hard state in
// each Save, so a torn Save can leave entries of a newer term than the stored term: the reload
// then takes that term, with no vote.) Any write or fsync error fails the storage for
// good (every later call returns that error): the node must stop.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "swarmbox/raft/file_system.hpp"
#include "swarmbox/raft/storage.hpp"

namespace swarmbox::raft {

class WalStorage final : public Storage {
 public:
  static constexpr std::uint32_t kMaxRecordBytes = 64u << 20;

  // `fs` must outlive the storage. Creates `dir` when missing.
  static Result<std::unique_ptr<WalStorage>> Open(FileSystem& fs, std::string dir);

  Result<PersistentState> Load() override;
  Status Save(const std::optional<HardState>& hard_state, std::span<const Entry> entries,
              const Snapshot& snapshot) override;
  Status Compact(const Snapshot& snapshot) override;

  // Bytes cut off the WAL's tail at Open (0 when the file ended cleanly).
  std::uint64_t torn_bytes_dropped() const { return torn_bytes_dropped_; }

 private:
  WalStorage(FileSystem& fs, std::string dir);
  Status Recover();
  // Rebuilds *st from the WAL's records; cuts off a torn last record.
  Status ReplayWal(const Bytes& data, PersistentState* st);
  // Puts the WAL's log onto the snapshot file's snapshot and repairs a hard state torn from its
  // entries.
  Status Reconcile(const Snapshot& file_snapshot, PersistentState* st) const;
  Status RewriteWal();
  Status Fail(Error e);

  FileSystem& fs_;
  std::string dir_;
  std::string wal_path_;
  std::string snapshot_path_;
  std::unique_ptr<AppendFile> wal_;
  PersistentState state_;  // mirror of what is durable
  std::optional<Error> failed_;
  std::uint64_t torn_bytes_dropped_ = 0;
};

}  // namespace swarmbox::raft
