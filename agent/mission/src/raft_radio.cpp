#include "swarmbox/mission/raft_radio.hpp"

#include <utility>

#include "swarmbox/mission/raft_envelope.hpp"

namespace swarmbox::mission {

RaftRadio::RaftRadio(std::string self, PayloadHandler on_payload)
    : self_(std::move(self)), on_payload_(std::move(on_payload)) {}

RaftRadio::~RaftRadio() {
  subscriber_.reset();  // waits for a running callback; none after this
  publisher_.reset();
}

Result<std::unique_ptr<RaftRadio>> RaftRadio::Create(bus::Participant& mesh, std::string self,
                                                     PayloadHandler on_payload) {
  if (auto s = bus::ValidateDroneName(self); !s) return s.error().Context("raft radio");
  if (!on_payload) return Error(ErrorCode::kInvalidArgument, "raft radio: no payload handler");
  std::unique_ptr<RaftRadio> radio(new RaftRadio(std::move(self), std::move(on_payload)));
  auto pub = mesh.CreatePublisher<bus::RaftMessage>(bus::kRaftTopic, bus::Qos::kRadio);
  if (!pub) return std::move(pub).error().Context("raft radio: creating the writer");
  radio->publisher_ = std::move(*pub);
  RaftRadio* raw = radio.get();
  auto sub = mesh.CreateSubscriber<bus::RaftMessage>(
      bus::kRaftTopic, bus::Qos::kRadio, [raw](const bus::RaftMessage& m) { raw->OnSample(m); });
  if (!sub) return std::move(sub).error().Context("raft radio: creating the reader");
  radio->subscriber_ = std::move(*sub);
  return radio;
}

void RaftRadio::Send(const std::string& to, std::span<const std::uint8_t> bytes) {
  const bus::RaftMessage m = WrapRaftPayload(self_, to, bytes);
  if (publisher_->Publish(m)) {
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

}  // namespace swarmbox::mission
