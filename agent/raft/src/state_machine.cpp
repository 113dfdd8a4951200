#include "swarmbox/raft/state_machine.hpp"

#include <algorithm>

#include "swarmbox/raft/detail/byte_io.hpp"

namespace swarmbox::raft {

void EntryLogMachine::Apply(std::uint64_t index, std::span<const std::uint8_t> data,
                            const EventOut& /*events*/) {
  SWARMBOX_CHECK(entries_.empty() || index > entries_.back().index);
  if (data.empty()) return;  // the leader's no-op
  entries_.push_back(Committed{index, Bytes(data.begin(), data.end())});
}

Bytes EntryLogMachine::Snapshot() const {
  Bytes out;
  detail::ByteWriter w(&out);
  w.U8(kSnapshotVersion);
  w.Varint(entries_.size());
  for (const Committed& c : entries_) {
    w.Varint(c.index);
    w.Blob(c.data);
  }
  return out;
}

Status EntryLogMachine::Restore(std::span<const std::uint8_t> snapshot) {
  auto bad = [](std::string what) {
    return Error(ErrorCode::kProtocol, std::move(what), "entry log snapshot");
  };
  detail::ByteReader r(snapshot);
  const std::uint8_t version = r.U8();
  if (r.ok() && version != kSnapshotVersion) {
    return bad("unsupported version " + std::to_string(version) + " (this build reads " +
               std::to_string(kSnapshotVersion) + ")");
  }
  const std::uint64_t n = r.Count(2, "entry");  // an index and a length byte at least
  std::vector<Committed> entries;
  entries.reserve(static_cast<std::size_t>(n));
  for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
    Committed c;
    c.index = r.Varint();
    c.data = r.Blob();
    if (!r.ok()) break;
    if (c.index == 0 || (!entries.empty() && c.index <= entries.back().index)) {
      return bad("entry " + std::to_string(k) + " has index " + std::to_string(c.index) +
                 ", not above the previous one");
    }
    if (c.data.empty()) return bad("entry at index " + std::to_string(c.index) + " is empty");
    entries.push_back(std::move(c));
  }
  if (r.ok() && !r.at_end()) r.Fail("trailing bytes");
  if (!r.ok()) return bad(r.error());
  entries_ = std::move(entries);
  return Ok{};
}

void EntryLogMachine::ReplayRestored(std::uint64_t after, std::vector<Committed>* out) const {
  auto it = std::upper_bound(entries_.begin(), entries_.end(), after,
                             [](std::uint64_t i, const Committed& c) { return i < c.index; });
  out->insert(out->end(), it, entries_.end());
}

}  // namespace swarmbox::raft
