#include "swarmbox/radio/dds_radio.hpp"

#include <algorithm>
#include <utility>

#include "swarmbox/bus/topics.hpp"
#include "swarmbox/raft_service/raft_envelope.hpp"

namespace swarmbox::radio {
namespace {

std::int64_t SteadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

DdsRadio::DdsRadio(std::string self, std::vector<std::string> peers)
    : self_(std::move(self)), peers_(std::move(peers)), now_ns_(SteadyNs()) {
  inbox_.reserve(256);
}

DdsRadio::~DdsRadio() {
  // Readers first: no callback runs after these return.
  brain_sub_.reset();
  state_sub_.reset();
  ping_sub_.reset();
  raft_.reset();
}

Result<std::unique_ptr<DdsRadio>> DdsRadio::Create(bus::Participant& mesh, std::string self,
                                                   DdsRadioOptions options) {
  if (auto s = bus::ValidateDroneName(self); !s) return s.error().Context("dds radio");
  std::vector<std::string> peers;
  for (const std::string& m : options.members) {
    if (auto s = bus::ValidateDroneName(m); !s) return s.error().Context("dds radio: member");
    if (m != self && std::find(peers.begin(), peers.end(), m) == peers.end()) peers.push_back(m);
  }
  if ((options.raft || options.pings) && peers.empty()) {
    return Error(ErrorCode::kInvalidArgument,
                 "dds radio: Raft and pings need another member besides '" + self + "'");
  }
  std::unique_ptr<DdsRadio> radio(new DdsRadio(std::move(self), std::move(peers)));
  auto sp = mesh.CreatePublisher<bus::DroneState>(bus::kDroneStateTopic, bus::Qos::kState);
  if (!sp) return sp.error().Context("dds radio: publishing drone state");
  radio->state_pub_ = std::move(*sp);
  auto dp = mesh.CreatePublisher<bus::Detection>(bus::kDetectionTopic, bus::Qos::kRadio);
  if (!dp) return dp.error().Context("dds radio: publishing detections");
  radio->detection_pub_ = std::move(*dp);
  if (options.pings) {
    if (auto s = radio->OpenPings(mesh); !s) return s.error();
  }
  if (options.raft) {
    if (auto s = radio->OpenRaft(mesh); !s) return s.error();
  }
  if (options.hear_states) {
    if (auto s = radio->HearStates(mesh); !s) return s.error();
  }
  if (options.brains) {
    if (auto s = radio->OpenBrains(mesh); !s) return s.error();
  }
  return radio;
}

Status DdsRadio::OpenPings(bus::Participant& mesh) {
  auto writer = [&mesh]() {
    return mesh.CreatePublisher<bus::RadioPing>(bus::kRadioPingTopic, bus::Qos::kRadio);
  };
  for (std::size_t i = 0; i < peers_.size(); ++i) {
    auto ping = writer();
    if (!ping) return ping.error().Context("dds radio: creating a ping writer");
    ping_writers_.push_back(std::move(*ping));
    auto pong = writer();
    if (!pong) return pong.error().Context("dds radio: creating a pong writer");
    pong_writers_.push_back(std::move(*pong));
  }
  auto other = writer();
  if (!other) return other.error().Context("dds radio: creating the pong writer");
  other_pong_writer_ = std::move(*other);
  auto sub = mesh.CreateSubscriber<bus::RadioPing>(bus::kRadioPingTopic, bus::Qos::kRadio,
                                                   [this](const bus::RadioPing& m) {
                                                     if (m.to != self_ || m.from == self_) return;
                                                     bus::RadioFrame f;
                                                     f.from = m.from;
                                                     f.to = m.to;
                                                     f.ping_msg.push_back(m);
                                                     Push(std::move(f));
                                                   });
  if (!sub) return sub.error().Context("dds radio: hearing pings");
  ping_sub_ = std::move(*sub);
  return Ok{};
}

Status DdsRadio::OpenRaft(bus::Participant& mesh) {
  auto rr = raft_service::RaftRadio::Create(mesh, self_, peers_, [this](std::span<const std::uint8_t> bytes) {
    bus::RadioFrame f;
    f.to = self_;
    bus::RaftMessage m;
    m.to = self_;
    m.term = raft_service::PeekRaftTerm(bytes);
    m.payload.assign(bytes.begin(), bytes.end());
    f.raft_msg.push_back(std::move(m));
    Push(std::move(f));
  });
  if (!rr) return rr.error().Context("dds radio: raft");
  raft_ = std::move(*rr);
  return Ok{};
}

Status DdsRadio::HearStates(bus::Participant& mesh) {
  auto sub = mesh.CreateSubscriber<bus::DroneState>(bus::kDroneStateTopic, bus::Qos::kState,
                                                    [this](const bus::DroneState& m) {
                                                      if (m.drone == self_) return;
                                                      bus::RadioFrame f;
                                                      f.from = m.drone;
                                                      f.state_msg.push_back(m);
                                                      Push(std::move(f));
                                                    });
  if (!sub) return sub.error().Context("dds radio: hearing drone states");
  state_sub_ = std::move(*sub);
  return Ok{};
}

Status DdsRadio::OpenBrains(bus::Participant& mesh) {
  auto bp = mesh.CreatePublisher<bus::BrainMessage>(bus::kBrainMessageTopic, bus::Qos::kRadio);
  if (!bp) return bp.error().Context("dds radio: publishing brain messages");
  brain_pub_ = std::move(*bp);
  auto sub = mesh.CreateSubscriber<bus::BrainMessage>(bus::kBrainMessageTopic, bus::Qos::kRadio,
                                                      [this](const bus::BrainMessage& m) {
                                                        if (m.from == self_) return;
                                                        if (!m.to.empty() && m.to != self_) return;
                                                        bus::RadioFrame f;
                                                        f.from = m.from;
                                                        f.to = m.to;
                                                        f.brain_msg.push_back(m);
                                                        Push(std::move(f));
                                                      });
  if (!sub) return sub.error().Context("dds radio: hearing brain messages");
  brain_sub_ = std::move(*sub);
  return Ok{};
}

void DdsRadio::Push(bus::RadioFrame frame) {
  frame.delivered_ns = SteadyNs();
  frame.size_bytes = FrameBytes(frame);
  std::lock_guard<std::mutex> lk(inbox_mu_);
  if (inbox_.size() >= kMaxInbox) {
    inbox_.erase(inbox_.begin());
    ++inbox_drops_;
  }
  inbox_.push_back(std::move(frame));
  ++received_;
}

DdsRadio::PingWriter& DdsRadio::PingWriterFor(const bus::RadioPing& m) {
  for (std::size_t i = 0; i < peers_.size(); ++i) {
    if (peers_[i] == m.to) return m.is_pong ? *pong_writers_[i] : *ping_writers_[i];
  }
  return *other_pong_writer_;
}

bool DdsRadio::Publish(const bus::RadioFrame& frame) {
  if (!frame.state_msg.empty()) return static_cast<bool>(state_pub_->Publish(frame.state_msg.front()));
  if (!frame.detection_msg.empty())
    return static_cast<bool>(detection_pub_->Publish(frame.detection_msg.front()));
  if (!frame.raft_msg.empty()) {
    if (!raft_) return false;
    const bus::RaftMessage& m = frame.raft_msg.front();
    raft_->Send(m.to.empty() ? frame.to : m.to, m.payload);  // RaftRadio counts its own failures
    return true;
  }
  if (!frame.ping_msg.empty()) {
    const bus::RadioPing& m = frame.ping_msg.front();
    if (!other_pong_writer_ ||
        (!m.is_pong && std::find(peers_.begin(), peers_.end(), m.to) == peers_.end())) {
      return false;  // no ping writers, or a ping to a drone that is not a member
    }
    return static_cast<bool>(PingWriterFor(m).Publish(m));
  }
  if (!frame.brain_msg.empty()) {
    if (!brain_pub_) return false;
    bus::BrainMessage m = frame.brain_msg.front();
    m.from = self_;
    if (m.to.empty()) m.to = frame.to;
    return static_cast<bool>(brain_pub_->Publish(m));
  }
  return false;
}

void DdsRadio::Send(bus::RadioFrame frame) {
  frame.from = self_;
  frame.seq = ++seq_;
  frame.sent_ns = SteadyNs();
  frame.size_bytes = FrameBytes(frame);
  // Best effort like the radio: a failure is counted, never retried.
  if (Publish(frame)) {
    ++sent_;
  } else {
    ++send_errors_;
  }
}

void DdsRadio::TakeReceived(const bus::SensorSample& /*sample*/, std::vector<bus::RadioFrame>* out) {
  now_ns_ = SteadyNs();
  std::lock_guard<std::mutex> lk(inbox_mu_);
  if (out->empty()) {
    out->swap(inbox_);  // the inbox keeps the capacity of the caller's (cleared) vector
  } else {
    for (bus::RadioFrame& f : inbox_) out->push_back(std::move(f));
  }
  inbox_.clear();
}

void DdsRadio::Flush(bus::ActuatorCommand* command) { command->radio_out.clear(); }

DdsRadio::Counters DdsRadio::counters() const {
  Counters c;
  c.sent = sent_;
  c.send_errors = send_errors_;
  std::lock_guard<std::mutex> lk(inbox_mu_);
  c.received = received_;
  c.inbox_drops = inbox_drops_;
  return c;
}

}  // namespace swarmbox::radio
