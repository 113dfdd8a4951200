// StateMachine: what a Raft node replicates. Raft agrees on a log of opaque byte entries; the
// state machine gives them meaning. Every node applies the same committed entries in the same
// order (Raft §5.3 State Machine Safety), so a deterministic machine reaches the same state on
// every drone. NodeDriver (node_driver.hpp) owns one and calls it; nothing else may.
//
//   auto machine = std::make_unique<EntryLogMachine>();        // or MissionStateMachine, or yours
//   auto node = NodeDriver::Open(cfg, wal, radio, clock, sink, std::move(machine));
//   (*node)->Propose(Bytes{'h', 'i'});
//   std::vector<Committed> got;
//   (*node)->TakeCommitted(&got);                             // {index, data} in index order
//
// The contract a machine keeps:
//   Apply(index, data, events)  called once per committed index, in strictly increasing index
//        order, never twice for an index (the driver skips what a restored snapshot covers).
//        `data` empty is the leader's no-op (Raft §8; NodeDriver refuses empty proposals, so an
//        empty entry is never an application's): advance, change nothing. Bytes the machine
//        cannot read must be handled deterministically (e.g. ignored, the same way on every
//        node): a committed entry cannot be refused. Must not throw, read clocks, draw random
//        numbers or do I/O beyond writing event lines through `events`.
//   Snapshot()  the whole state after the last Apply (or Restore), as bytes (Raft §7): the
//        driver compacts its log with it and sends it to a node too far behind.
//   Restore(bytes)  replaces the whole state with a Snapshot() of the same kind of machine (taken
//        on any node). kProtocol (or another error) for bytes it cannot read: the node then
//        stops (NodeDriver::stopped()) or fails to open, since it cannot know the state.
//   OnSnapshotInstalled(index, events)  after Restore of a snapshot the leader sent while
//        running (not of the snapshot found in storage at start-up): the machine's event lines
//        for it, if any. Default: none.
//   ReplayRestored(after, out)  after any Restore (start-up or the leader's): the entries the
//        restored state holds with index > `after`, in index order, for NodeDriver's
//        committed-entries tap. Default: none (the restored state stands for them). EntryLogMachine
//        hands back the entries it keeps.
// Determinism: same entries in, same Snapshot() bytes out, on every node (the cluster simulator
// checks exactly that after every step).
// Threading: none; the driver's thread calls everything.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/types.hpp"

namespace swarmbox::raft {

using EventSink = std::function<void(const LogEvent&)>;

// One committed log entry as an application sees it (the tap's and EntryLogMachine's unit).
struct Committed {
  std::uint64_t index = 0;  // the Raft log index: increasing, not contiguous (no-ops are left out)
  Bytes data;               // never empty
  bool operator==(const Committed&) const = default;
};

// Where Apply writes its event lines: stamped with the node's name and the driver clock's `t`
// (simulated seconds in the agent) at the moment of the apply.
//   events.Emit(events.New("mission_state").Add("state", "SEARCH").Add("index", index));
class EventOut {
 public:
  EventOut(double t_s, std::string_view node, const EventSink& sink)
      : t_s_(t_s), node_(node), sink_(sink) {}
  LogEvent New(std::string_view event) const { return LogEvent(t_s_, node_, event); }
  void Emit(const LogEvent& e) const {
    if (sink_) sink_(e);
  }
  double t_s() const { return t_s_; }
  std::string_view node() const { return node_; }

 private:
  double t_s_;
  std::string_view node_;
  const EventSink& sink_;
};

class StateMachine {
 public:
  virtual ~StateMachine() = default;
  virtual void Apply(std::uint64_t index, std::span<const std::uint8_t> data,
                     const EventOut& events) = 0;
  virtual Bytes Snapshot() const = 0;
  virtual Status Restore(std::span<const std::uint8_t> snapshot) = 0;
  virtual void OnSnapshotInstalled(std::uint64_t /*index*/, const EventOut& /*events*/) {}
  virtual void ReplayRestored(std::uint64_t /*after*/, std::vector<Committed>* /*out*/) const {}
};

// Keeps every committed (non-empty) entry; its snapshot is all of them. The machine for
// applications whose meaning lives elsewhere (a brain without a ReplicatedState reads the log
// from the tap), and a replay of the whole log after a restart. Memory grows with the log.
// Snapshot encoding: version (1 byte, kSnapshotVersion), the entry count (LEB128 varint), then
// per entry its index (varint, strictly increasing) and its data (varint length, bytes).
// Apply ignores the leader's no-ops (empty data): entries() holds application entries only.
class EntryLogMachine final : public StateMachine {
 public:
  static constexpr std::uint8_t kSnapshotVersion = 1;

  void Apply(std::uint64_t index, std::span<const std::uint8_t> data,
             const EventOut& events) override;
  Bytes Snapshot() const override;
  Status Restore(std::span<const std::uint8_t> snapshot) override;
  void ReplayRestored(std::uint64_t after, std::vector<Committed>* out) const override;

  const std::vector<Committed>& entries() const { return entries_; }

 private:
  std::vector<Committed> entries_;
};

}  // namespace swarmbox::raft
