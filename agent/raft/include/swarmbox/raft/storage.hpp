// Storage: where a Raft node keeps its durable state (Raft §5 Figure 2 "persistent state": term,
// vote, log; plus the latest snapshot, §7). The node driver calls Save() for every Ready *before*
// sending the Ready's messages, so a vote or an acknowledgement is never sent for state that a
// crash could lose.
//
// Real: WalStorage (wal_storage.hpp), a checksummed write-ahead file with fsync. Fake:
// sim::MemoryStorage (agent/raft/sim), durable across simulated crashes.
//
// Errors are final for the node: after a failed Save the durable state is unknown, so the driver
// stops (NodeDriver::stopped()) and reports the error rather than carrying on.
#pragma once

#include <optional>
#include <span>

#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/raw_node.hpp"
#include "swarmbox/raft/types.hpp"

namespace swarmbox::raft {

class Storage {
 public:
  virtual ~Storage() = default;

  // The durable state; an empty PersistentState for a node that never ran.
  // Errors: kIo (cannot read), kProtocol (corrupt data, with where it is).
  virtual Result<PersistentState> Load() = 0;

  // Makes durable, in this order: a snapshot received from the leader (non-empty `snapshot`:
  // replaces the whole log), then `entries` (overwriting any stored entry >= entries[0].index),
  // then the hard state. Returns only once all of it would survive a crash (fsync).
  virtual Status Save(const std::optional<HardState>& hard_state, std::span<const Entry> entries,
                      const Snapshot& snapshot) = 0;

  // Durably records a snapshot the node took itself (log compaction, Raft §7) and may drop the
  // stored entries <= snapshot.index.
  virtual Status Compact(const Snapshot& snapshot) = 0;
};

}  // namespace swarmbox::raft
