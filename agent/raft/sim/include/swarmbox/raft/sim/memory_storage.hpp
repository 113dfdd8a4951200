// MemoryStorage: the fake Storage (STYLE.md 3). Keeps the "durable" state in memory, so a
// simulated crash (destroying the NodeDriver) and restart (a new NodeDriver on the same
// MemoryStorage) behaves like a process restart on a disk that kept every completed Save.
// FailNextSave() injects a storage failure for tests of the stop-loudly path.
#pragma once

#include <optional>

#include "swarmbox/raft/storage.hpp"

namespace swarmbox::raft::sim {

class MemoryStorage : public Storage {
 public:
  Result<PersistentState> Load() override;
  Status Save(const std::optional<HardState>& hard_state, std::span<const Entry> entries,
              const Snapshot& snapshot) override;
  Status Compact(const Snapshot& snapshot) override;

  void FailNextSave(Error error) { fail_next_ = std::move(error); }
  const PersistentState& state() const { return state_; }
  std::uint64_t last_index() const { return state_.snapshot.index + state_.entries.size(); }
  // Term of stored entry i (the snapshot's at its index), nullopt when not stored.
  std::optional<std::uint64_t> Term(std::uint64_t i) const;
  std::uint64_t saves() const { return saves_; }

 private:
  PersistentState state_;
  std::optional<Error> fail_next_;
  std::uint64_t saves_ = 0;
};

}  // namespace swarmbox::raft::sim
