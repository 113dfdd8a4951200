// MeshRadio: how an agent talks to the other drones, whichever radio model the trial runs
// (ARCHITECTURE.md, "Time" and "Two networks per trial"). Everything an agent says to its peers
// (its DroneState, detections, Raft messages, link pings, its brain's messages) is a bus::RadioFrame handed to Send();
// everything it hears comes out of TakeReceived(), once per lockstep step, in delivery order.
//
//   radio.model channel (ChannelRadio): no mesh network at all. Send() queues the frame; Flush()
//     moves the queue into the step's ActuatorCommand (radio_out), the physics server's channel
//     decides whether and when each frame arrives, and the receiver finds it in a later
//     SensorSample (radio_in). Deterministic: what an agent hears at a step depends only on the
//     simulated world, the trial and its seed.
//   radio.model netem (DdsRadio): the real network stack. Send() publishes on the mesh DDS topics
//     (bus/topics.hpp) over the `mesh` Docker network, impaired by netem or its userspace
//     fallback on the wall clock; what arrived since the last step is handed out at the next one.
//
//   radio->Send(frame);                               // from the control loop only
//   radio->TakeReceived(sample, &frames);             // every step, before the agent decides
//   radio->Flush(&command);                           // every step, before the command goes out
//
// Send() fills `from`, `seq` (per sender, from 1), `sent_ns` (the radio's clock, now_ns(): the
// step's simulated time with channel, set by the last TakeReceived) and `size_bytes` (FrameBytes below); the caller sets `to` ("" =
// broadcast) and exactly one of state_msg / detection_msg / raft_msg / ping_msg / brain_msg.
//
// Thread-safety: one thread (the agent's control loop) calls every member. An implementation may
// receive on middleware threads internally. Ownership: the radio outlives nothing it is given.
#pragma once

#include <cstdint>
#include <vector>

#include "swarmbox/bus/messages.hpp"

namespace swarmbox::radio {

class MeshRadio {
 public:
  virtual ~MeshRadio() = default;

  // Queues (channel) or sends (netem) one frame; see the banner for the fields it fills.
  virtual void Send(bus::RadioFrame frame) = 0;
  // Appends to `out` the frames received for the step of `sample` (the channel's radio_in, or
  // what the mesh delivered since the previous call), in delivery order; sets the radio's clock
  // (now_ns()). Each frame's delivered_ns is on that clock.
  virtual void TakeReceived(const bus::SensorSample& sample, std::vector<bus::RadioFrame>* out) = 0;
  // Channel: moves the frames sent since the last Flush into `command->radio_out` (replacing its
  // contents). Netem: clears `command->radio_out` (the frames went out on the mesh already).
  virtual void Flush(bus::ActuatorCommand* command) = 0;
  // The radio's clock as set by the last TakeReceived [ns]: the sample's simulated time (channel),
  // the steady clock when it was called (netem). Raft ticks and the link probe run on it.
  virtual std::int64_t now_ns() const = 0;
};

// The bytes a frame occupies on the air, the figure the channel charges airtime for: the payload's
// encoded size plus the headers a real mesh would add (RTPS 20 + submessage 24 + UDP 8 + IPv4 20 +
// 802.11 MAC 34 = 106 bytes). A pure function of the frame, so every model counts the same.
std::uint32_t FrameBytes(const bus::RadioFrame& frame);

}  // namespace swarmbox::radio
