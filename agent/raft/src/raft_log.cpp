#include "swarmbox/raft/raft_log.hpp"

#include <algorithm>
#include <iterator>

#include "swarmbox/common/result.hpp"

namespace swarmbox::raft {

RaftLog::RaftLog(const Snapshot& snapshot, std::vector<Entry> entries, std::uint64_t commit)
    : snapshot_index_(snapshot.index), snapshot_term_(snapshot.term), entries_(std::move(entries)) {
  for (std::size_t k = 0; k < entries_.size(); ++k) {
    SWARMBOX_CHECK(entries_[k].index == snapshot_index_ + 1 + k);
  }
  committed_ = std::clamp(commit, snapshot_index_, last_index());
  applied_ = snapshot_index_;
  stable_index_ = last_index();
}

std::uint64_t RaftLog::last_term() const {
  return entries_.empty() ? snapshot_term_ : entries_.back().term;
}

std::optional<std::uint64_t> RaftLog::Term(std::uint64_t i) const {
  if (i == snapshot_index_) return snapshot_term_;
  if (i < snapshot_index_ || i > last_index()) return std::nullopt;
  return entries_[i - snapshot_index_ - 1].term;
}

bool RaftLog::MatchTerm(std::uint64_t i, std::uint64_t term) const {
  auto t = Term(i);
  return t && *t == term;
}

const Entry& RaftLog::At(std::uint64_t i) const {
  SWARMBOX_CHECK(i > snapshot_index_ && i <= last_index());
  return entries_[i - snapshot_index_ - 1];
}

bool RaftLog::IsUpToDate(std::uint64_t index, std::uint64_t term) const {
  const std::uint64_t lt = last_term();
  return term > lt || (term == lt && index >= last_index());
}

std::optional<std::uint64_t> RaftLog::MaybeAppend(std::uint64_t prev_index,
                                                  std::uint64_t prev_term,
                                                  std::uint64_t leader_commit,
                                                  std::span<const Entry> entries) {
  // Receiver rule 2: reply false if the log has no entry at prev_index whose term matches.
  // An index inside our snapshot is committed, hence matches (Log Matching, Raft §5.3).
  if (prev_index < snapshot_index_) {
    // Skip the entries our snapshot already covers.
    const std::uint64_t skip = std::min<std::uint64_t>(snapshot_index_ - prev_index, entries.size());
    entries = entries.subspan(static_cast<std::size_t>(skip));
    prev_index += skip;
    if (entries.empty() && prev_index < snapshot_index_) {
      CommitTo(std::min(leader_commit, snapshot_index_));
      return prev_index;
    }
    prev_term = *Term(prev_index);
  }
  if (!MatchTerm(prev_index, prev_term)) return std::nullopt;
  const std::uint64_t last_new = prev_index + entries.size();
  // Rules 3-4: delete a conflicting suffix and append entries not already in the log. Entries we
  // already hold with the same term are kept as they are (a delayed, duplicated append must not
  // truncate entries appended after it).
  std::size_t k = 0;
  for (; k < entries.size(); ++k) {
    const Entry& e = entries[k];
    if (!MatchTerm(e.index, e.term)) break;
  }
  if (k < entries.size()) {
    SWARMBOX_CHECK(entries[k].index > committed_);  // a committed entry never conflicts
    Append(entries.subspan(k));
  }
  // Rule 5: commit = min(leaderCommit, index of last new entry).
  CommitTo(std::min(leader_commit, last_new));
  return last_new;
}

void RaftLog::Append(std::span<const Entry> entries) {
  if (entries.empty()) return;
  const std::uint64_t first = entries.front().index;
  SWARMBOX_CHECK(first > committed_ && first > snapshot_index_ && first <= last_index() + 1);
  entries_.resize(static_cast<std::size_t>(first - snapshot_index_ - 1));
  for (const Entry& e : entries) {
    SWARMBOX_CHECK(e.index == last_index() + 1);
    entries_.push_back(e);
  }
  stable_index_ = std::min(stable_index_, first - 1);
}

std::vector<Entry> RaftLog::Slice(std::uint64_t lo, std::uint64_t hi, std::size_t max_count) const {
  SWARMBOX_CHECK(lo >= first_index() && hi <= last_index() + 1);
  std::vector<Entry> out;
  if (lo >= hi) return out;
  if (hi - lo > max_count) hi = lo + max_count;
  auto begin = entries_.begin() + static_cast<std::ptrdiff_t>(lo - snapshot_index_ - 1);
  out.assign(begin, begin + static_cast<std::ptrdiff_t>(hi - lo));
  return out;
}

void RaftLog::CommitTo(std::uint64_t index) {
  if (index <= committed_) return;
  SWARMBOX_CHECK(index <= last_index());
  committed_ = index;
}

bool RaftLog::MaybeCommit(std::uint64_t index, std::uint64_t term) {
  if (index > committed_ && MatchTerm(index, term)) {
    CommitTo(index);
    return true;
  }
  return false;
}

void RaftLog::AppliedTo(std::uint64_t index) {
  SWARMBOX_CHECK(index <= committed_);
  applied_ = std::max(applied_, index);
}

void RaftLog::StableTo(std::uint64_t index) {
  stable_index_ = std::max(stable_index_, std::min(index, last_index()));
}

void RaftLog::Restore(const Snapshot& snapshot) {
  SWARMBOX_CHECK(snapshot.index >= committed_);
  snapshot_index_ = snapshot.index;
  snapshot_term_ = snapshot.term;
  entries_.clear();
  committed_ = applied_ = stable_index_ = snapshot.index;
}

void RaftLog::Compact(std::uint64_t index) {
  if (index <= snapshot_index_) return;
  SWARMBOX_CHECK(index <= applied_ && index <= last_index());
  const std::uint64_t term = *Term(index);
  entries_.erase(entries_.begin(), entries_.begin() + static_cast<std::ptrdiff_t>(index - snapshot_index_));
  snapshot_index_ = index;
  snapshot_term_ = term;
  stable_index_ = std::max(stable_index_, index);
}

}  // namespace swarmbox::raft
