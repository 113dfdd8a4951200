// PayloadInbox: received Raft payloads handed from middleware threads to the loop that drives a
// RaftService (raft_service.hpp is not thread-safe and has no thread).
//
//   PayloadInbox inbox;                                      // before the radio: outlives it
//   auto radio = RaftRadio::Create(mesh, self, members, [&](std::span<const std::uint8_t> b) {
//     inbox.Push(b);                                         // middleware thread: copies, never blocks long
//   });
//   std::vector<raft::Bytes> batch;
//   loop: inbox.WaitUntil(deadline);                         // optional: wake on the first arrival
//         inbox.Drain(&batch);                               // arrival order
//         for (const auto& b : batch) service->OnPayload(b);
//         service->Tick();
//
// Bounded: beyond `capacity` payloads waiting, the oldest is dropped (as the radio would drop
// it) and counted in drops(): a stalled loop must not buffer without bound.
// Thread-safety: every member is thread-safe.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <span>
#include <vector>

#include "swarmbox/raft/types.hpp"

namespace swarmbox::raft_service {

class PayloadInbox {
 public:
  static constexpr std::size_t kDefaultCapacity = 1024;

  explicit PayloadInbox(std::size_t capacity = kDefaultCapacity);

  // Copies `bytes` in (any thread).
  void Push(std::span<const std::uint8_t> bytes);
  // Moves every waiting payload, in arrival order, to the end of `out`; returns how many.
  std::size_t Drain(std::vector<raft::Bytes>* out);
  // Waits until a payload is waiting or `deadline` passes; true when one is waiting. Only for a
  // loop on the wall clock (swarmbox-raft-node): a simulated-time loop never waits on it.
  bool WaitUntil(std::chrono::steady_clock::time_point deadline) const;

  std::size_t size() const;
  std::uint64_t drops() const;  // payloads dropped because the inbox was full

 private:
  const std::size_t capacity_;
  mutable std::mutex mu_;
  mutable std::condition_variable cv_;
  std::deque<raft::Bytes> items_;
  std::uint64_t drops_ = 0;
};

}  // namespace swarmbox::raft_service
