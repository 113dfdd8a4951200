// RaftService: one drone's Raft node running on wall-clock time over the mesh radio.
//
// Owns a raft::NodeDriver (node_driver.hpp), its WalStorage in `data_dir`, and a RaftRadio
// (raft_radio.hpp) on the caller's mesh bus::Participant. One thread of its own calls Tick()
// every tick_ms of wall-clock time and feeds the bytes the radio received into the driver; the
// driver is not thread-safe, so that thread and the public calls share one lock.
//
//   RaftServiceConfig cfg;
//   cfg.driver.self = "scout_1";
//   cfg.driver.members = {"scout_1", "scout_2", "lifter"};  // the trial's drones, on every drone
//   cfg.driver.seed = trial_seed;
//   ReadRaftOptions(trial_raft_mapping, &cfg.driver);       // per-trial timings (optional)
//   cfg.data_dir = "/var/lib/swarmbox/raft";
//   auto raft = RaftService::Start(cfg, *mesh, sim_clock);   // prints events on stdout
//   if (!raft) { print raft.error(); exit(1); }
//   (*raft)->Propose(raft::StartSearch{});   // any thread; kUnavailable: no leader yet, retry
//   raft::MissionState m = (*raft)->mission();   // a copy of the committed mission
//   if ((*raft)->WaitStopped(100ms)) exit(1);    // storage failed: the node must die loudly
//
// Events: the driver's contract events (event=leader_elected, mission_state, victim_confirmed,
// victim_status, raft_stopped) go to `out` as logfmt lines, `t` from the caller's `sim_clock`.
// The default `out` writes each line to stdout and flushes (log watchers match them live).
// Received bytes the driver cannot decode are counted (protocol_errors()), not fatal.
//
// Failure: when the driver stops (a storage write or fsync failed: it can no longer promise what
// it voted or acknowledged) the thread prints event=raft_stopped (the driver does), ends, and
// health() / WaitStopped() report the error; every later Propose returns it. The caller must
// then exit non-zero.
//
// Thread-safety: every public member is thread-safe. `out` is called with the service's lock
// held (from the service thread or from a Propose caller): it must not call back into the
// service. Ownership: `mesh` and `sim_clock` must outlive the service; the destructor stops the
// thread, then the radio (no callback after it returns), then closes the storage.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "swarmbox/bus/participant.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/mission/raft_radio.hpp"
#include "swarmbox/raft/file_system.hpp"
#include "swarmbox/raft/mission_state.hpp"
#include "swarmbox/raft/node_driver.hpp"
#include "swarmbox/raft/wal_storage.hpp"

namespace swarmbox::mission {

struct RaftServiceConfig {
  raft::DriverConfig driver;  // self, members, seed, timings (tick_ms drives the service thread)
  std::string data_dir;       // WAL and snapshot directory, created when missing
  // Received samples waiting for the service thread beyond this are dropped, oldest first (as
  // the radio would): a stalled node must not buffer without bound.
  std::size_t max_inbox = 1024;
  // The file system of the WAL; nullptr = the real one (PosixFileSystem). Tests inject failures.
  // Must outlive the service.
  raft::FileSystem* file_system = nullptr;
};

// One logfmt line per call, without a trailing newline.
using LineSink = std::function<void(const std::string& line)>;
// Writes the line and '\n' to stdout and flushes.
void PrintLineToStdout(const std::string& line);

class RaftService {
 public:
  // Opens the storage (replaying the WAL), the radio and the driver, then starts the thread.
  // Errors: a bad DriverConfig (kInvalidArgument), storage that cannot be read (kIo/kProtocol),
  // the radio's bus errors.
  static Result<std::unique_ptr<RaftService>> Start(const RaftServiceConfig& config,
                                                    bus::Participant& mesh,
                                                    const raft::Clock& sim_clock,
                                                    LineSink out = PrintLineToStdout);
  ~RaftService();
  RaftService(const RaftService&) = delete;
  RaftService& operator=(const RaftService&) = delete;

  // Proposes a mission command (encoded by the driver). kUnavailable when this node knows no
  // leader to forward to; the stop error once stopped.
  Status Propose(const raft::MissionCommand& command);
  // Starts an election now (tests, the "kill the leader" fault's bookkeeping).
  Status Campaign();

  raft::MissionState mission() const;  // a copy of the committed (applied) mission state
  std::string leader() const;          // "" when none known
  bool is_leader() const;
  std::uint64_t term() const;
  std::uint64_t commit_index() const;

  // Ok while running; the driver's stop error once it stopped.
  Status health() const;
  // Waits up to `timeout` for the driver to stop; true when it has (then exit non-zero).
  bool WaitStopped(std::chrono::milliseconds timeout) const;

  RaftRadio::Counters radio_counters() const { return radio_->counters(); }
  std::uint64_t protocol_errors() const;  // undecodable/misaddressed payloads dropped
  std::uint64_t inbox_drops() const;      // samples dropped because the inbox was full
  const std::string& self() const { return config_.driver.self; }

 private:
  explicit RaftService(RaftServiceConfig config, LineSink out);
  void OnPayload(std::span<const std::uint8_t> bytes);  // middleware thread
  void Run();                                           // the service thread
  void MarkStopped();                                   // with mu_ held

  RaftServiceConfig config_;
  LineSink out_;
  std::unique_ptr<raft::FileSystem> own_fs_;  // when config_.file_system is null
  std::unique_ptr<raft::WalStorage> wal_;

  // Received payloads, handed from the radio's middleware thread to the service thread.
  mutable std::mutex inbox_mu_;
  std::condition_variable inbox_cv_;
  std::deque<raft::Bytes> inbox_;
  bool quit_ = false;
  std::uint64_t inbox_drops_ = 0;

  std::unique_ptr<RaftRadio> radio_;  // after the inbox: destroyed before it

  // The driver and what is guarded with it.
  mutable std::mutex mu_;
  mutable std::condition_variable stopped_cv_;
  std::unique_ptr<raft::NodeDriver> driver_;  // after radio_ and wal_: destroyed before them
  std::optional<Error> stop_error_;
  std::uint64_t protocol_errors_ = 0;

  std::thread thread_;
};

}  // namespace swarmbox::mission
