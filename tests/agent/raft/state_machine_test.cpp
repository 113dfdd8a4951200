// The replicated state machines behind NodeDriver (state_machine.hpp): the entry log (every
// committed entry, its snapshot, its replay) and the SAR mission (its event lines, byte for byte
// the lines the driver printed before the StateMachine interface: the contract of the logs).
#include "swarmbox/raft/state_machine.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "swarmbox/raft/mission_state_machine.hpp"

namespace swarmbox::raft {
namespace {

Bytes B(std::string_view s) { return Bytes(s.begin(), s.end()); }

class Lines {
 public:
  EventOut At(double t_s, std::string_view node) { return EventOut(t_s, node, sink_); }
  std::vector<std::string> lines;

 private:
  EventSink sink_ = [this](const LogEvent& e) { lines.push_back(e.str()); };
};

TEST(EntryLogMachine, KeepsEveryCommittedEntryInIndexOrderAndSkipsNoops) {
  Lines out;
  EntryLogMachine m;
  m.Apply(1, {}, out.At(0, "a"));  // the leader's no-op
  m.Apply(2, B("pos a 1.000 2.000"), out.At(0, "a"));
  m.Apply(3, {}, out.At(0, "a"));
  m.Apply(5, B("arrived a"), out.At(0, "a"));
  EXPECT_EQ(m.entries(), (std::vector<Committed>{{2, B("pos a 1.000 2.000")}, {5, B("arrived a")}}));
  EXPECT_TRUE(out.lines.empty());  // the entry log prints nothing
}

TEST(EntryLogMachine, SnapshotRestoresTheSameEntriesAndReplaysThemAfterAnIndex) {
  Lines out;
  EntryLogMachine a;
  for (std::uint64_t i = 1; i <= 40; ++i) {
    if (i % 3 == 0) {
      a.Apply(i, {}, out.At(0, "a"));
    } else {
      a.Apply(i, B("entry " + std::to_string(i) + std::string(i * 7, 'x')), out.At(0, "a"));
    }
  }
  const Bytes snap = a.Snapshot();
  EntryLogMachine b;
  b.Apply(1, B("to be replaced"), out.At(0, "b"));
  ASSERT_TRUE(b.Restore(snap).ok());
  EXPECT_EQ(b.entries(), a.entries());
  EXPECT_EQ(b.Snapshot(), snap);  // same state, same bytes (the simulator's safety check)

  std::vector<Committed> replay;
  b.ReplayRestored(0, &replay);
  EXPECT_EQ(replay, a.entries());
  replay.clear();
  b.ReplayRestored(30, &replay);  // what a node that had applied up to 30 has not seen yet
  ASSERT_EQ(replay.size(), 7u);   // 31 32 34 35 37 38 40
  EXPECT_EQ(replay.front().index, 31u);
  EXPECT_EQ(replay.back().index, 40u);
  replay.clear();
  b.ReplayRestored(40, &replay);
  EXPECT_TRUE(replay.empty());

  EntryLogMachine empty;
  ASSERT_TRUE(b.Restore(empty.Snapshot()).ok());
  EXPECT_TRUE(b.entries().empty());
}

TEST(EntryLogMachine, RestoreRefusesWhatIsNotItsSnapshotAndKeepsItsState) {
  Lines out;
  EntryLogMachine m;
  m.Apply(4, B("kept"), out.At(0, "a"));
  EntryLogMachine src;
  src.Apply(2, B("one"), out.At(0, "a"));
  src.Apply(3, B("two"), out.At(0, "a"));
  const Bytes good = src.Snapshot();
  auto expect_error = [&](const Bytes& bytes, const std::string& message) {
    Status s = m.Restore(bytes);
    ASSERT_FALSE(s.ok()) << message;
    EXPECT_EQ(s.error().code(), ErrorCode::kProtocol);
    EXPECT_EQ(s.error().ToString(), "entry log snapshot: " + message);
    EXPECT_EQ(m.entries(), (std::vector<Committed>{{4, B("kept")}}));
  };
  expect_error(MissionState().EncodeSnapshot(), "not an entry log snapshot (no \"sbel\" magic)");
  Bytes v = good;
  v[4] = 9;
  expect_error(v, "unsupported version 9 (this build reads 1)");
  Bytes trailing = good;
  trailing.push_back(0);
  expect_error(trailing, "trailing bytes at byte 16");
  Bytes truncated(good.begin(), good.end() - 1);
  expect_error(truncated, "truncated bytes (need 3, have 2) at byte 13");
  // Two entries at index 2 and 3 -> make the second one's index 2: not increasing.
  Bytes order = good;
  order[11] = 2;  // "sbel" 1 count=2 | idx=2 len=3 "one" | idx=3 len=3 "two"
  expect_error(order, "entry 1 has index 2, not above the previous one");
  // Every truncation is an error, never a crash or an out-of-bounds read.
  for (std::size_t n = 0; n < good.size(); ++n) {
    EXPECT_FALSE(m.Restore(std::span<const std::uint8_t>(good.data(), n)).ok()) << n;
  }
}

// The mission's lines, as NodeDriver printed them before they moved behind the machine
// (cluster_sim_test's MissionEventsAreByteIdenticalToThePreStateMachineDriver checks whole runs).
TEST(MissionStateMachine, PrintsTheMissionEventLinesOfTheLogContract) {
  Lines out;
  MissionStateMachine m;
  m.Apply(1, {}, out.At(1.0, "scout_1"));  // no-op: advances, prints nothing
  EXPECT_EQ(m.mission().applied_index(), 1u);
  m.Apply(2, EncodeCommand(StartSearch{}), out.At(1.5, "scout_1"));
  m.Apply(3, EncodeCommand(ConfirmVictim{"scout_2", 41.5, -12}), out.At(2.25, "scout_1"));
  m.Apply(4, EncodeCommand(ConvergeOn{1}), out.At(3, "scout_1"));
  m.Apply(5, EncodeCommand(BeginRescue{1, "lifter"}), out.At(4, "scout_1"));
  m.Apply(6, EncodeCommand(MarkRescued{1}), out.At(5, "scout_1"));
  m.Apply(7, EncodeCommand(ConvergeOn{9}), out.At(6, "scout_1"));  // rejected: prints nothing
  m.Apply(8, B("\x07garbage"), out.At(7, "scout_1"));              // undecodable: nothing
  EXPECT_EQ(m.mission().applied_index(), 8u);
  EXPECT_EQ(out.lines, (std::vector<std::string>{
                           "t=1.500 node=scout_1 event=mission_state state=SEARCH index=2",
                           "t=2.250 node=scout_1 event=victim_confirmed id=1 x=41.500 y=-12.000 index=3",
                           "t=3.000 node=scout_1 event=mission_state state=CONVERGE index=4",
                           "t=4.000 node=scout_1 event=mission_state state=RESCUE index=5",
                           "t=4.000 node=scout_1 event=victim_status id=1 status=being_rescued rescuer=lifter index=5",
                           "t=5.000 node=scout_1 event=victim_status id=1 status=rescued rescuer=lifter index=6",
                           "t=5.000 node=scout_1 event=mission_state state=SEARCH index=6",
                       }));
}

TEST(MissionStateMachine, SnapshotRoundTripsAndAnInstalledSnapshotSaysSo) {
  Lines out;
  MissionStateMachine a;
  a.Apply(1, EncodeCommand(StartSearch{}), out.At(0, "a"));
  a.Apply(2, EncodeCommand(ReportSighting{"a", 1, 3, 4, 0.95}), out.At(0, "a"));
  EXPECT_EQ(a.Snapshot(), a.mission().EncodeSnapshot());
  MissionStateMachine b;
  ASSERT_TRUE(b.Restore(a.Snapshot()).ok());
  EXPECT_EQ(b.mission(), a.mission());
  out.lines.clear();
  b.OnSnapshotInstalled(2, out.At(9.5, "b"));
  EXPECT_EQ(out.lines, (std::vector<std::string>{
                           "t=9.500 node=b event=mission_state state=SEARCH index=2 from=snapshot"}));
  std::vector<Committed> replay;
  b.ReplayRestored(0, &replay);
  EXPECT_TRUE(replay.empty());  // the mission stands for its entries
  Status s = b.Restore(EntryLogMachine().Snapshot());
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(b.mission(), a.mission());
}

}  // namespace
}  // namespace swarmbox::raft
