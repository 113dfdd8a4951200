// DdsRadio: the MeshRadio of radio.model netem (mesh_radio.hpp): the real network stack. Frames
// go out as the mesh DDS topics of before (bus/topics.hpp), over the `mesh` Docker network that
// netem or its userspace fallback impairs on the wall clock:
//   state_msg      bus::DroneState on kDroneStateTopic (Qos::kState)
//   detection_msg  bus::Detection on kDetectionTopic (Qos::kRadio)
//   raft_msg       raft_service::RaftRadio on kRaftTopic (its lanes: kLanesPerPeer writers per member)
//   ping_msg       bus::RadioPing on kRadioPingTopic (Qos::kRadio), one writer per peer for pings
//                  and one per peer for pongs (a best-effort reader drops what one writer's stream
//                  reorders: radio_link history in agent/radio/README.md), one for anyone else
//   brain_msg      bus::BrainMessage on kBrainMessageTopic (Qos::kRadio), with options.brains:
//                  heard when addressed to us or to everyone ("") and not our own
//
//   DdsRadioOptions o;  o.members = {"scout_1", "scout_2"};  o.raft = o.pings = o.hear_states = true;
//   auto radio = DdsRadio::Create(*mesh, "scout_1", o);   // bad name or a bus error: an error
//   radio->TakeReceived(sample, &frames);                // what arrived since the last call
//
// Receiving: the middleware callbacks (DroneStates of others, pings/pongs addressed to us, Raft
// payloads RaftRadio delivers to us, brain messages for us) push a frame into a mutex-guarded inbox, stamped
// delivered_ns = the steady clock at arrival; TakeReceived drains it in arrival order. The inbox
// keeps at most kMaxInbox frames (oldest dropped, counted: a stalled control loop must not buffer
// without bound). Detections are sent, not heard (no agent consumes them; recorders listen).
// The radio's clock (now_ns) is the steady clock at the last TakeReceived; sent_ns is the steady
// clock at Send. Flush only clears command->radio_out: the frames went out at Send.
// Received Raft frames carry raft_msg {from "" (RaftRadio hands over the payload only), to self,
// term, payload}.
//
// Thread-safety: Send/TakeReceived/Flush from the control loop only (never from a callback);
// callbacks run on middleware threads and only touch the inbox. Cyclone delivers a write to the
// same process's readers synchronously in the writing thread: Send publishes without holding the
// inbox lock, so our own samples (dropped by the callbacks) cannot deadlock. Ownership: destroy
// the radio before the participant; the destructor removes the readers first (no callback after).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "swarmbox/bus/participant.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/raft_service/raft_radio.hpp"
#include "swarmbox/radio/mesh_radio.hpp"

namespace swarmbox::radio {

struct DdsRadioOptions {
  std::vector<std::string> members;  // the trial's drones (self dropped): Raft lanes, ping writers
  bool raft = false;                 // carry raft_msg (raft_service::RaftRadio); needs members
  bool pings = false;                // ping/pong writers per member, hear mesh/ping; needs members
  bool hear_states = false;          // hear the others' DroneStates (the SAR mission's peers)
  bool brains = false;               // carry brain_msg (send and hear mesh/brain)
};

class DdsRadio final : public MeshRadio {
 public:
  static constexpr std::size_t kMaxInbox = 4096;

  struct Counters {
    std::uint64_t sent = 0;         // frames published
    std::uint64_t send_errors = 0;  // publish failures, or a kind this radio does not carry
    std::uint64_t received = 0;     // frames put in the inbox
    std::uint64_t inbox_drops = 0;  // dropped because the inbox was full
  };

  // kInvalidArgument for a bad drone name, or raft/pings without another member; the bus errors
  // of creating a writer or reader otherwise.
  static Result<std::unique_ptr<DdsRadio>> Create(bus::Participant& mesh, std::string self,
                                                  DdsRadioOptions options);
  ~DdsRadio() override;
  DdsRadio(const DdsRadio&) = delete;
  DdsRadio& operator=(const DdsRadio&) = delete;

  void Send(bus::RadioFrame frame) override;
  void TakeReceived(const bus::SensorSample& sample, std::vector<bus::RadioFrame>* out) override;
  void Flush(bus::ActuatorCommand* command) override;
  std::int64_t now_ns() const override { return now_ns_; }

  Counters counters() const;
  const std::string& self() const { return self_; }

 private:
  using PingWriter = bus::Publisher<bus::RadioPing>;
  DdsRadio(std::string self, std::vector<std::string> peers);
  // Create's optional parts (DdsRadioOptions): a ping and a pong writer per peer and the ping
  // reader; Raft over the radio; the neighbours' states; brain messages. Callbacks run on
  // middleware threads and only Push().
  Status OpenPings(bus::Participant& mesh);
  Status OpenRaft(bus::Participant& mesh);
  Status HearStates(bus::Participant& mesh);
  Status OpenBrains(bus::Participant& mesh);
  void Push(bus::RadioFrame frame);  // middleware threads
  PingWriter& PingWriterFor(const bus::RadioPing& m);
  bool Publish(const bus::RadioFrame& frame);

  std::string self_;
  std::vector<std::string> peers_;  // members without self, Create's order
  std::int64_t now_ns_ = 0;
  std::uint64_t seq_ = 0;
  std::uint64_t sent_ = 0;
  std::uint64_t send_errors_ = 0;

  mutable std::mutex inbox_mu_;  // guards inbox_, received_, inbox_drops_
  std::vector<bus::RadioFrame> inbox_;
  std::uint64_t received_ = 0;
  std::uint64_t inbox_drops_ = 0;

  std::unique_ptr<bus::Publisher<bus::DroneState>> state_pub_;
  std::unique_ptr<bus::Publisher<bus::Detection>> detection_pub_;
  std::unique_ptr<bus::Publisher<bus::BrainMessage>> brain_pub_;
  std::vector<std::unique_ptr<PingWriter>> ping_writers_;  // per peer
  std::vector<std::unique_ptr<PingWriter>> pong_writers_;  // per peer
  std::unique_ptr<PingWriter> other_pong_writer_;
  // Declared last: destroyed first, so no callback runs into a half-destroyed radio.
  std::unique_ptr<raft_service::RaftRadio> raft_;
  std::unique_ptr<bus::Subscriber<bus::RadioPing>> ping_sub_;
  std::unique_ptr<bus::Subscriber<bus::DroneState>> state_sub_;
  std::unique_ptr<bus::Subscriber<bus::BrainMessage>> brain_sub_;
};

}  // namespace swarmbox::radio
