#include "swarmbox/radio/mesh_radio.hpp"

#include <cstddef>

namespace swarmbox::radio {
namespace {

// Plain CDR sizes without alignment padding (the figure is an airtime estimate, not a codec):
// a string is a 4-byte length, its bytes and the terminating NUL; a sequence a 4-byte length and
// its elements.
constexpr std::size_t kHeaders = 20 + 24 + 8 + 20 + 34;  // RTPS, DATA submessage, UDP, IPv4, 802.11 MAC

std::size_t Str(const std::string& s) { return 4 + s.size() + 1; }

std::size_t Payload(const bus::RadioFrame& f) {
  std::size_t n = 0;
  for (const bus::DroneState& s : f.state_msg) n += Str(s.drone) + 8 + 8 + 8 + 3 * 8 + 3 * 8 + 8 + 8 + Str(s.mode);
  for (const bus::Detection& d : f.detection_msg) n += Str(d.from) + 8 + 8 + Str(d.label) + 8 + 3 * 8 + 8;
  for (const bus::RaftMessage& r : f.raft_msg) n += Str(r.from) + Str(r.to) + 8 + 4 + r.payload.size();
  for (const bus::RadioPing& p : f.ping_msg) n += Str(p.from) + Str(p.to) + 8 + 8 + 1;
  for (const bus::BrainMessage& b : f.brain_msg) n += Str(b.from) + Str(b.to) + Str(b.topic) + 4 + b.payload.size();
  return n;
}

}  // namespace

std::uint32_t FrameBytes(const bus::RadioFrame& frame) {
  return static_cast<std::uint32_t>(kHeaders + Payload(frame));
}

}  // namespace swarmbox::radio
