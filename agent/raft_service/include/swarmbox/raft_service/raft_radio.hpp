// RaftRadio: raft::Transport over the mesh radio, i.e. the bus topic bus::kRaftTopic with
// Qos::kRadio (best effort, keep-last 256, no retransmission of ours: Raft does its own retries
// and loss on the radio stays visible to it).
//
//   auto radio = RaftRadio::Create(*mesh, "scout_1", {"scout_2", "scout_3"},
//                                  [&](std::span<const std::uint8_t> bytes) {
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
// Writers: kLanesPerPeer writers per peer named at Create, used in turn, plus one shared writer for
// any other destination. A best-effort DDS reader drops a sample that arrives after a later sample
// of the same writer (RTPS sequence numbers), so a radio with jitter (netem and the NFQUEUE delayer
// both reorder packets) would turn reordering into extra loss on one shared writer: a heartbeat
// broadcast is four samples at once, and the reader of each peer sees all four (measured in
// raft_service_radio_reorder_test at 50 +- 20 ms / 5 %: 52.7 % of a leader's messages to one
// follower lost with one writer, 4.0 % with these lanes). With a writer of its own per destination
// a reader only loses what its own stream reorders, and with two lanes per peer two messages sent
// to one peer back to back (an append and a heartbeat, a response pair) are on different writers
// too: only two messages to one peer whose send times differ by less than the jitter and with a
// third in between can still overtake each other and lose the older one. The radio's loss itself
// is untouched (still best effort, nothing retransmitted), and Raft sees reordering as the radio
// made it. Duplicates a radio makes of one sample are dropped by the reader (one sequence number).
//
// Thread-safety: Send() may be called from any thread (the bus publisher is thread-safe; the writer
// table never changes after Create). `on_payload` runs on a middleware thread, one call at a time;
// the span is valid during the call only. Destroying the radio waits for a running callback to
// return, and no callback runs after. Ownership: the radio's publishers/subscriber share the
// participant's middleware objects (they may outlive the Participant object, see participant.hpp).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "swarmbox/bus/participant.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/raft/node_driver.hpp"

namespace swarmbox::raft_service {

class RaftRadio final : public raft::Transport {
 public:
  using PayloadHandler = std::function<void(std::span<const std::uint8_t>)>;

  struct Counters {
    std::uint64_t sent = 0;          // samples published
    std::uint64_t send_errors = 0;   // Publish() failures (dropped, like radio loss)
    std::uint64_t delivered = 0;     // samples handed to on_payload
    std::uint64_t ignored = 0;       // samples for other drones, our own, or empty
  };

  // Writers per named peer, used in turn (see the banner).
  static constexpr int kLanesPerPeer = 2;

  // `peers`: the destinations that get writers of their own (self and repeats are skipped; Raft's
  // members). kInvalidArgument for a bad drone name (bus::ValidateDroneName) of self or a peer or
  // no handler; the bus errors of creating a writer or the reader otherwise.
  static Result<std::unique_ptr<RaftRadio>> Create(bus::Participant& mesh, std::string self,
                                                   std::vector<std::string> peers,
                                                   PayloadHandler on_payload);
  // Without peers: every destination shares one writer (fine on a radio that does not reorder).
  static Result<std::unique_ptr<RaftRadio>> Create(bus::Participant& mesh, std::string self,
                                                   PayloadHandler on_payload) {
    return Create(mesh, std::move(self), {}, std::move(on_payload));
  }
  ~RaftRadio() override;
  RaftRadio(const RaftRadio&) = delete;
  RaftRadio& operator=(const RaftRadio&) = delete;

  void Send(const std::string& to, std::span<const std::uint8_t> bytes) override;

  Counters counters() const;
  const std::string& self() const { return self_; }
  // The peers with writers of their own, in Create's order (self and repeats removed).
  const std::vector<std::string>& peers() const { return peers_; }
  // Readers matched by the writer(s) that carry samples to `to` (the fewest over its lanes; the
  // shared writer for a destination not named at Create), our own reader included.
  int matched_subscribers(const std::string& to) const;
  // Readers matched by the shared writer (other processes' and our own).
  int matched_subscribers() const { return shared_->MatchedSubscribers(); }
  // Writers matched by our reader (each peer's writers and our own).
  int matched_publishers() const { return subscriber_->MatchedPublishers(); }

 private:
  using Writer = bus::Publisher<bus::RaftMessage>;
  struct Lanes {
    std::vector<std::unique_ptr<Writer>> writers;  // kLanesPerPeer, never empty
    std::atomic<std::uint32_t> next{0};            // the lane of the next Send, mod size
  };
  RaftRadio(std::string self, std::vector<std::string> peers, PayloadHandler on_payload);
  void OnSample(const bus::RaftMessage& m);
  Writer& WriterFor(const std::string& to);

  std::string self_;
  PayloadHandler on_payload_;
  std::atomic<std::uint64_t> sent_{0};
  std::atomic<std::uint64_t> send_errors_{0};
  std::atomic<std::uint64_t> delivered_{0};
  std::atomic<std::uint64_t> ignored_{0};
  std::vector<std::string> peers_;
  std::vector<std::unique_ptr<Lanes>> lanes_;  // lanes_[i] carries samples to peers_[i]
  std::unique_ptr<Writer> shared_;             // any other destination
  // Declared last: destroyed first, so no callback runs into a half-destroyed radio.
  std::unique_ptr<bus::Subscriber<bus::RaftMessage>> subscriber_;
};

}  // namespace swarmbox::raft_service
