#include "swarmbox/radio/channel_radio.hpp"

#include <utility>

namespace swarmbox::radio {

void ChannelRadio::Send(bus::RadioFrame frame) {
  frame.from = self_;
  frame.seq = ++seq_;
  frame.sent_ns = now_ns_;
  frame.delivered_ns = 0;
  frame.size_bytes = FrameBytes(frame);
  queue_.push_back(std::move(frame));
}

void ChannelRadio::TakeReceived(const bus::SensorSample& sample, std::vector<bus::RadioFrame>* out) {
  now_ns_ = sample.sim_time_ns;
  out->insert(out->end(), sample.radio_in.begin(), sample.radio_in.end());
}

void ChannelRadio::Flush(bus::ActuatorCommand* command) {
  // Swap, then clear: the queue keeps the command's old capacity for the next step.
  command->radio_out.swap(queue_);
  queue_.clear();
}

}  // namespace swarmbox::radio
