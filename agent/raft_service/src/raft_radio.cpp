#include "swarmbox/raft_service/raft_radio.hpp"

#include <algorithm>
#include <utility>

#include "swarmbox/raft_service/raft_envelope.hpp"

namespace swarmbox::raft_service {

RaftRadio::RaftRadio(std::string self, std::vector<std::string> peers, PayloadHandler on_payload)
    : self_(std::move(self)), on_payload_(std::move(on_payload)), peers_(std::move(peers)) {}

RaftRadio::~RaftRadio() {
  subscriber_.reset();  // waits for a running callback; none after this
  lanes_.clear();
  shared_.reset();
}

Result<std::unique_ptr<RaftRadio>> RaftRadio::Create(bus::Participant& mesh, std::string self,
                                                     std::vector<std::string> peers,
                                                     PayloadHandler on_payload) {
  if (auto s = bus::ValidateDroneName(self); !s) return s.error().Context("raft radio");
  if (!on_payload) return Error(ErrorCode::kInvalidArgument, "raft radio: no payload handler");
  std::vector<std::string> unique;
  for (std::string& p : peers) {
    if (auto s = bus::ValidateDroneName(p); !s) return s.error().Context("raft radio: peer");
    if (p == self || std::find(unique.begin(), unique.end(), p) != unique.end()) continue;
    unique.push_back(std::move(p));
  }
  std::unique_ptr<RaftRadio> radio(
      new RaftRadio(std::move(self), std::move(unique), std::move(on_payload)));
  auto writer = [&mesh]() {
    return mesh.CreatePublisher<bus::RaftMessage>(bus::kRaftTopic, bus::Qos::kRadio);
  };
  // One stream per destination and lane (see the header: a best-effort reader drops what arrives
  // out of order within one writer's stream).
  for (std::size_t i = 0; i < radio->peers_.size(); ++i) {
    auto lanes = std::make_unique<Lanes>();
    for (int lane = 0; lane < kLanesPerPeer; ++lane) {
      auto pub = writer();
      if (!pub) {
        return std::move(pub).error().Context("raft radio: creating a writer to " + radio->peers_[i]);
      }
      lanes->writers.push_back(std::move(*pub));
    }
    radio->lanes_.push_back(std::move(lanes));
  }
  auto shared = writer();
  if (!shared) return std::move(shared).error().Context("raft radio: creating the writer");
  radio->shared_ = std::move(*shared);
  RaftRadio* raw = radio.get();
  auto sub = mesh.CreateSubscriber<bus::RaftMessage>(
      bus::kRaftTopic, bus::Qos::kRadio, [raw](const bus::RaftMessage& m) { raw->OnSample(m); });
  if (!sub) return std::move(sub).error().Context("raft radio: creating the reader");
  radio->subscriber_ = std::move(*sub);
  return radio;
}

RaftRadio::Writer& RaftRadio::WriterFor(const std::string& to) {
  for (std::size_t i = 0; i < peers_.size(); ++i) {  // a handful of peers: a scan beats a map
    if (peers_[i] == to) {
      Lanes& l = *lanes_[i];
      const std::uint32_t lane = l.next.fetch_add(1, std::memory_order_relaxed);
      return *l.writers[lane % l.writers.size()];
    }
  }
  return *shared_;
}

int RaftRadio::matched_subscribers(const std::string& to) const {
  for (std::size_t i = 0; i < peers_.size(); ++i) {
    if (peers_[i] != to) continue;
    int fewest = lanes_[i]->writers.front()->MatchedSubscribers();
    for (const auto& w : lanes_[i]->writers) fewest = std::min(fewest, w->MatchedSubscribers());
    return fewest;
  }
  return shared_->MatchedSubscribers();
}

void RaftRadio::Send(const std::string& to, std::span<const std::uint8_t> bytes) {
  const bus::RaftMessage m = WrapRaftPayload(self_, to, bytes);
  if (WriterFor(to).Publish(m)) {
    sent_.fetch_add(1, std::memory_order_relaxed);
  } else {
    send_errors_.fetch_add(1, std::memory_order_relaxed);
  }
}

void RaftRadio::OnSample(const bus::RaftMessage& m) {
  if (ClassifyRaftMessage(m, self_) != RaftDelivery::kDeliver) {
    ignored_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  delivered_.fetch_add(1, std::memory_order_relaxed);
  on_payload_(std::span<const std::uint8_t>(m.payload));
}

RaftRadio::Counters RaftRadio::counters() const {
  Counters c;
  c.sent = sent_.load(std::memory_order_relaxed);
  c.send_errors = send_errors_.load(std::memory_order_relaxed);
  c.delivered = delivered_.load(std::memory_order_relaxed);
  c.ignored = ignored_.load(std::memory_order_relaxed);
  return c;
}

}  // namespace swarmbox::raft_service
