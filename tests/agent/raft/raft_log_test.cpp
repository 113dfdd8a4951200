// RaftLog: the log operations behind AppendEntries (Raft §5.3) and the election restriction
// (§5.4.1).
#include "swarmbox/raft/raft_log.hpp"

#include <gtest/gtest.h>

namespace swarmbox::raft {
namespace {

std::vector<Entry> Ents(std::initializer_list<std::pair<std::uint64_t, std::uint64_t>> it) {
  std::vector<Entry> out;
  for (auto [index, term] : it) out.push_back(Entry{term, index, EntryType::kNormal, {}});
  return out;
}

RaftLog LogWith(std::initializer_list<std::pair<std::uint64_t, std::uint64_t>> it) {
  return RaftLog(Snapshot{}, Ents(it), 0);
}

TEST(RaftLog, TermOfIndexesInsideAndOutside) {
  RaftLog log(Snapshot{3, 2, {}}, Ents({{4, 2}, {5, 3}}), 3);
  EXPECT_EQ(log.Term(3), 2u);
  EXPECT_EQ(log.Term(5), 3u);
  EXPECT_EQ(log.Term(2), std::nullopt);  // compacted
  EXPECT_EQ(log.Term(6), std::nullopt);  // beyond the end
  EXPECT_EQ(log.first_index(), 4u);
  EXPECT_EQ(log.last_index(), 5u);
}

// Raft §5.3 receiver rule 2: reject when the log has no entry at prevLogIndex with prevLogTerm.
TEST(RaftLog, MaybeAppendRejectsMissingPrevEntry) {
  RaftLog log = LogWith({{1, 1}, {2, 1}});
  EXPECT_EQ(log.MaybeAppend(2, 2, 0, Ents({{3, 2}})), std::nullopt);
  EXPECT_EQ(log.MaybeAppend(3, 1, 0, Ents({{4, 1}})), std::nullopt);
  EXPECT_EQ(log.last_index(), 2u);
}

// Rules 3-4: a conflicting entry and all that follow it are deleted, then new entries appended.
TEST(RaftLog, MaybeAppendTruncatesConflictingSuffix) {
  RaftLog log = LogWith({{1, 1}, {2, 1}, {3, 1}});
  log.StableTo(3);
  EXPECT_EQ(log.MaybeAppend(1, 1, 0, Ents({{2, 2}})), 2u);
  EXPECT_EQ(log.last_index(), 2u);
  EXPECT_EQ(log.Term(2), 2u);
  EXPECT_EQ(log.stable_index(), 1u);  // index 2 must be rewritten to storage
}

// A delayed duplicate of an older append must not truncate entries appended after it.
TEST(RaftLog, MaybeAppendKeepsMatchingEntriesBeyondAStaleAppend) {
  RaftLog log = LogWith({{1, 1}, {2, 1}, {3, 1}});
  EXPECT_EQ(log.MaybeAppend(0, 0, 0, Ents({{1, 1}})), 1u);
  EXPECT_EQ(log.last_index(), 3u);
}

// Rule 5: commit = min(leaderCommit, index of last new entry).
TEST(RaftLog, MaybeAppendCommitsUpToLastNewEntry) {
  RaftLog log = LogWith({{1, 1}, {2, 1}, {3, 1}});
  EXPECT_EQ(log.MaybeAppend(1, 1, 3, Ents({{2, 1}})), 2u);
  EXPECT_EQ(log.committed(), 2u);
}

// Raft §5.4.1: up-to-date means a later last term, or the same term and a log at least as long.
TEST(RaftLog, IsUpToDateComparesLastTermThenLength) {
  RaftLog log = LogWith({{1, 1}, {2, 2}});
  EXPECT_TRUE(log.IsUpToDate(1, 3));
  EXPECT_TRUE(log.IsUpToDate(2, 2));
  EXPECT_TRUE(log.IsUpToDate(5, 2));
  EXPECT_FALSE(log.IsUpToDate(1, 2));
  EXPECT_FALSE(log.IsUpToDate(9, 1));
}

// Raft §5.4.2: a leader only commits by counting replicas an entry of its current term.
TEST(RaftLog, MaybeCommitOnlyEntriesOfTheGivenTerm) {
  RaftLog log = LogWith({{1, 1}, {2, 2}});
  EXPECT_FALSE(log.MaybeCommit(1, 2));
  EXPECT_EQ(log.committed(), 0u);
  EXPECT_TRUE(log.MaybeCommit(2, 2));
  EXPECT_EQ(log.committed(), 2u);
}

// Raft §7: compaction keeps the term of the last compacted entry.
TEST(RaftLog, CompactKeepsSnapshotTermAndLaterEntries) {
  RaftLog log = LogWith({{1, 1}, {2, 1}, {3, 2}});
  log.CommitTo(3);
  log.AppliedTo(2);
  log.Compact(2);
  EXPECT_EQ(log.snapshot_index(), 2u);
  EXPECT_EQ(log.Term(2), 1u);
  EXPECT_EQ(log.At(3).term, 2u);
  EXPECT_EQ(log.Slice(3, 4, 10).size(), 1u);
}

TEST(RaftLog, RestoreReplacesTheLog) {
  RaftLog log = LogWith({{1, 1}, {2, 1}});
  log.Restore(Snapshot{10, 3, {}});
  EXPECT_EQ(log.last_index(), 10u);
  EXPECT_EQ(log.last_term(), 3u);
  EXPECT_EQ(log.committed(), 10u);
  EXPECT_EQ(log.applied(), 10u);
}

}  // namespace
}  // namespace swarmbox::raft
