// ChannelRadio: the MeshRadio of radio.model channel (mesh_radio.hpp). Pure: no DDS, no clock of
// its own, no threads. The physics server's simulated channel carries every frame; this class
// only moves frames between the agent and the lockstep messages.
//
//   ChannelRadio radio("scout_1");
//   radio.TakeReceived(sample, &frames);   // sample.radio_in, in the order the channel sorted it
//                                          // ((delivered_ns, from, seq)); the clock := sim time
//   radio.Send(frame);                     // queued, stamped with that step's simulated time
//   radio.Flush(&command);                 // the queue -> command.radio_out (replaced), emptied
//
// The radio's clock is the simulated time of the last TakeReceived (now_ns(); 0 before the first),
// so a frame sent at step k leaves with sent_ns = t_k: the channel hands it to the air at t_k.
// Nothing here looks at a wall clock. Not thread-safe (the control loop owns it).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmbox/radio/mesh_radio.hpp"

namespace swarmbox::radio {

class ChannelRadio final : public MeshRadio {
 public:
  explicit ChannelRadio(std::string self) : self_(std::move(self)) {}

  void Send(bus::RadioFrame frame) override;
  void TakeReceived(const bus::SensorSample& sample, std::vector<bus::RadioFrame>* out) override;
  void Flush(bus::ActuatorCommand* command) override;

  // The simulated time of the last TakeReceived [ns].
  std::int64_t now_ns() const override { return now_ns_; }
  const std::string& self() const { return self_; }
  // Frames sent so far (the last seq handed out).
  std::uint64_t sent() const { return seq_; }
  // Frames waiting for the next Flush.
  std::size_t queued() const { return queue_.size(); }

 private:
  std::string self_;
  std::int64_t now_ns_ = 0;
  std::uint64_t seq_ = 0;
  std::vector<bus::RadioFrame> queue_;
};

}  // namespace swarmbox::radio
