#include "swarmbox/raft/sim/memory_storage.hpp"

namespace swarmbox::raft::sim {

Result<PersistentState> MemoryStorage::Load() { return state_; }

std::optional<std::uint64_t> MemoryStorage::Term(std::uint64_t i) const {
  if (i == state_.snapshot.index) return state_.snapshot.term;
  if (i < state_.snapshot.index || i > last_index()) return std::nullopt;
  return state_.entries[i - state_.snapshot.index - 1].term;
}

Status MemoryStorage::Save(const std::optional<HardState>& hard_state,
                           std::span<const Entry> entries, const Snapshot& snapshot) {
  if (fail_next_) {
    Error e = std::move(*fail_next_);
    fail_next_.reset();
    return e;
  }
  ++saves_;
  if (!snapshot.empty()) {
    state_.snapshot = snapshot;
    state_.entries.clear();
    if (state_.hard_state.commit < snapshot.index) state_.hard_state.commit = snapshot.index;
  }
  for (const Entry& e : entries) {
    const std::uint64_t base = state_.snapshot.index;
    if (e.index <= base || e.index > last_index() + 1) {
      return Error(ErrorCode::kInternal,
                   "entry " + std::to_string(e.index) + " does not follow the stored log",
                   "memory storage");
    }
    state_.entries.resize(static_cast<std::size_t>(e.index - base - 1));
    state_.entries.push_back(e);
  }
  if (hard_state) state_.hard_state = *hard_state;
  return Ok{};
}

Status MemoryStorage::Compact(const Snapshot& snapshot) {
  const std::uint64_t base = state_.snapshot.index;
  if (snapshot.index <= base || snapshot.index > last_index()) {
    return Error(ErrorCode::kInvalidArgument,
                 "compact to " + std::to_string(snapshot.index) + " outside the stored log",
                 "memory storage");
  }
  state_.entries.erase(state_.entries.begin(),
                       state_.entries.begin() + static_cast<std::ptrdiff_t>(snapshot.index - base));
  state_.snapshot = snapshot;
  return Ok{};
}

}  // namespace swarmbox::raft::sim
