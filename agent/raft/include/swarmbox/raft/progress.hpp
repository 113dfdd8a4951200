// Progress: the leader's view of one follower's log (Raft §5.3 nextIndex/matchIndex), with the
// flow-control states of etcd-io/raft's tracker: probe (one append per heartbeat until the match
// point is found), replicate (optimistic pipelining) and snapshot (waiting for InstallSnapshot).
#pragma once

#include <cstdint>

namespace swarmbox::raft {

struct Progress {
  enum class State : std::uint8_t { kProbe, kReplicate, kSnapshot };

  std::uint64_t match = 0;  // highest index known replicated on the follower
  std::uint64_t next = 1;   // next index to send
  State state = State::kProbe;
  bool probe_sent = false;        // probe: an append is in flight, wait for a reply or heartbeat
  std::uint64_t pending_snapshot = 0;  // snapshot: index of the snapshot sent
  bool recent_active = false;     // heard from since the last CheckQuorum (thesis §6.2)
  int inactive_ticks = 0;         // leader ticks since this peer last answered (replacement policy)
  bool heard = false;             // answered this leader at least once

  bool IsPaused() const {
    return state == State::kSnapshot || (state == State::kProbe && probe_sent);
  }
  void BecomeProbe() {
    if (state == State::kSnapshot) {
      next = (match > pending_snapshot ? match : pending_snapshot) + 1;
      pending_snapshot = 0;
    } else {
      next = match + 1;
    }
    state = State::kProbe;
    probe_sent = false;
  }
  void BecomeReplicate() {
    state = State::kReplicate;
    next = match + 1;
    probe_sent = false;
  }
  void BecomeSnapshot(std::uint64_t snapshot_index) {
    state = State::kSnapshot;
    pending_snapshot = snapshot_index;
  }
  // A successful append response up to `index`. Returns whether match moved.
  bool MaybeUpdate(std::uint64_t index) {
    bool updated = false;
    if (match < index) {
      match = index;
      updated = true;
      probe_sent = false;
    }
    if (next < index + 1) next = index + 1;
    return updated;
  }
  // A rejected append of `rejected` (the prev index we sent); `hint` is the follower's last index.
  // Returns false when the rejection is stale (an answer to an older append).
  bool MaybeDecrTo(std::uint64_t rejected, std::uint64_t hint) {
    if (state == State::kReplicate) {
      if (rejected <= match) return false;
      next = match + 1;
      return true;
    }
    if (next == 0 || next - 1 != rejected) return false;
    std::uint64_t n = rejected < hint + 1 ? rejected : hint + 1;
    next = n < 1 ? 1 : n;
    if (next <= match) next = match + 1;
    probe_sent = false;
    return true;
  }
};

}  // namespace swarmbox::raft
