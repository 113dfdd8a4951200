// RaftRadio: raft::Transport over the mesh radio, i.e. the bus topic bus::kRaftTopic with
// Qos::kRadio (best effort, keep-last 256, no retransmission of ours: Raft does its own retries
// and loss on the radio stays visible to it).
//
//   auto radio = RaftRadio::Create(*mesh, "scout_1", [&](std::span<const std::uint8_t> bytes) {
//     inbox.Push(bytes);            // called on a middleware thread: hand over, do not block
//   });
//   if (!radio) return radio.error();
//   NodeDriver::Open(cfg, wal, **radio, clock, sink);   // Send(to, bytes) = one sample
//
// Send(to, bytes) publishes one bus::RaftMessage {from = self, to, term (peeked), payload}.
// The subscriber on the same topic hands the payloads of samples addressed to `self` by another
// drone to `on_payload` (raft_envelope.hpp: ClassifyRaftMessage); everything else is counted and
// dropped. Publish errors are counted, never retried (best effort).
//
// Thread-safety: Send() may be called from any thread (the bus publisher is thread-safe).
// `on_payload` runs on a middleware thread, one call at a time; the span is valid during the call
// only. Destroying the radio waits for a running callback to return, and no callback runs after.
// Ownership: the radio's publisher/subscriber share the participant's middleware objects (they
// may outlive the Participant object, see participant.hpp).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "swarmbox/bus/participant.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/node_driver.hpp"

namespace swarmbox::mission {

class RaftRadio final : public raft::Transport {
 public:
  using PayloadHandler = std::function<void(std::span<const std::uint8_t>)>;

  struct Counters {
    std::uint64_t sent = 0;          // samples published
    std::uint64_t send_errors = 0;   // Publish() failures (dropped, like radio loss)
    std::uint64_t delivered = 0;     // samples handed to on_payload
    std::uint64_t ignored = 0;       // samples for other drones, our own, or empty
  };

  // kInvalidArgument for a bad drone name (bus::ValidateDroneName); the bus errors of creating
  // the writer or reader otherwise.
  static Result<std::unique_ptr<RaftRadio>> Create(bus::Participant& mesh, std::string self,
                                                   PayloadHandler on_payload);
  ~RaftRadio() override;
  RaftRadio(const RaftRadio&) = delete;
  RaftRadio& operator=(const RaftRadio&) = delete;

  void Send(const std::string& to, std::span<const std::uint8_t> bytes) override;

  Counters counters() const;
  const std::string& self() const { return self_; }
  // Other processes' (and our own) readers/writers matched on the radio topic.
  int matched_subscribers() const { return publisher_->MatchedSubscribers(); }
  int matched_publishers() const { return subscriber_->MatchedPublishers(); }

 private:
  RaftRadio(std::string self, PayloadHandler on_payload);
  void OnSample(const bus::RaftMessage& m);

  std::string self_;
  PayloadHandler on_payload_;
  std::atomic<std::uint64_t> sent_{0};
  std::atomic<std::uint64_t> send_errors_{0};
  std::atomic<std::uint64_t> delivered_{0};
  std::atomic<std::uint64_t> ignored_{0};
  std::unique_ptr<bus::Publisher<bus::RaftMessage>> publisher_;
  // Declared last: destroyed first, so no callback runs into a half-destroyed radio.
  std::unique_ptr<bus::Subscriber<bus::RaftMessage>> subscriber_;
};

}  // namespace swarmbox::mission
