// RaftLog: the in-memory Raft log of one node, after its latest snapshot.
//
// Holds entries (snapshot_index, last_index], the commit and applied indexes, and how far the log
// is known to be durable (`stable_index`): entries above it are "unstable" and are handed to the
// caller in Ready::entries to persist. Truncating a conflicting suffix (Raft §5.3) pulls
// stable_index back, so the caller rewrites the overwritten indexes. Pure: no I/O.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "swarmbox/raft/types.hpp"

namespace swarmbox::raft {

class RaftLog {
 public:
  // A log restored from durable state: snapshot (may be empty) then entries (contiguous, after it).
  RaftLog(const Snapshot& snapshot, std::vector<Entry> entries, std::uint64_t commit);
  RaftLog() = default;

  std::uint64_t snapshot_index() const { return snapshot_index_; }
  std::uint64_t snapshot_term() const { return snapshot_term_; }
  std::uint64_t first_index() const { return snapshot_index_ + 1; }
  std::uint64_t last_index() const { return snapshot_index_ + entries_.size(); }
  std::uint64_t last_term() const;
  std::uint64_t committed() const { return committed_; }
  std::uint64_t applied() const { return applied_; }
  std::uint64_t stable_index() const { return stable_index_; }

  // Term of entry i: the snapshot's term at snapshot_index, nullopt when compacted or beyond the end.
  std::optional<std::uint64_t> Term(std::uint64_t i) const;
  bool MatchTerm(std::uint64_t i, std::uint64_t term) const;
  const Entry& At(std::uint64_t i) const;  // i in [first_index, last_index]; aborts otherwise

  // Raft §5.4.1: is a log ending at (last_index, last_term) at least as up-to-date as ours?
  bool IsUpToDate(std::uint64_t last_index, std::uint64_t last_term) const;

  // Follower side of AppendEntries (Raft §5.3, Figure 2 receiver rules 2-5). Returns the index of
  // the last new entry, or nullopt when our log has no entry (prev_index, prev_term).
  std::optional<std::uint64_t> MaybeAppend(std::uint64_t prev_index, std::uint64_t prev_term,
                                           std::uint64_t leader_commit,
                                           std::span<const Entry> entries);
  // Appends after truncating any suffix from entries[0].index on. Entries must start within
  // [first_index, last_index + 1] and above committed (committed entries are never truncated).
  void Append(std::span<const Entry> entries);

  // Entries [lo, hi) with lo >= first_index, at most max_count of them.
  std::vector<Entry> Slice(std::uint64_t lo, std::uint64_t hi, std::size_t max_count) const;

  void CommitTo(std::uint64_t index);  // never moves backwards; index <= last_index
  // Leader: commit `index` if its entry is from `term` (Raft §5.4.2: only entries of the current
  // term are committed by counting replicas). Returns whether the commit index moved.
  bool MaybeCommit(std::uint64_t index, std::uint64_t term);
  void AppliedTo(std::uint64_t index);  // index <= committed
  void StableTo(std::uint64_t index);   // the caller persisted entries up to index

  // Replaces the whole log by a snapshot (Raft §7, receiver rule 7): commit = applied = its index.
  void Restore(const Snapshot& snapshot);
  // Drops entries <= index (already in a snapshot with that index). index <= applied.
  void Compact(std::uint64_t index);

 private:
  std::uint64_t snapshot_index_ = 0;
  std::uint64_t snapshot_term_ = 0;
  std::vector<Entry> entries_;  // entries_[k].index == snapshot_index_ + 1 + k
  std::uint64_t committed_ = 0;
  std::uint64_t applied_ = 0;
  std::uint64_t stable_index_ = 0;
};

}  // namespace swarmbox::raft
