// Helpers shared by the channel tests: a simple profile built in code, line-ups of drones, and a
// loop that sends at a fixed period and collects the deliveries.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "swarmbox/channel/channel.hpp"

namespace swarmbox::channel::testing {

inline std::string TrialsDir() { return SWARMBOX_TRIALS_DIR; }

// A clean radio: no shadowing, everything within 1 km hears everything (PER ~0 at 100 m),
// 1 Mb/s, 100 us of overhead, 50 frames per queue.
inline RadioProfile CleanProfile() {
  RadioProfile p;
  p.name = "clean";
  p.frequency_mhz = 5180;
  p.tx_power_dbm = 15;
  p.antenna_gain_dbi = 0;
  p.noise_floor_dbm = -91;
  p.path_loss = {2.0, 46.7, 1.0, 0.0, 20.0};
  p.obstacle_loss_db = 20;
  p.per = {0.1, 0.45};
  p.max_range_m = 1000;
  p.data_rate_bps = 1e6;
  p.capacity_bps = 1e6;
  p.frame_overhead_us = 100;
  p.queue_frames = 50;
  return p;
}

// n drones on the x axis, `spacing_m` apart, 20 m up.
inline std::vector<Vec3d> LineUp(std::size_t n, double spacing_m) {
  std::vector<Vec3d> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = {static_cast<double>(i) * spacing_m, 0.0, 20.0};
  return v;
}

// Steps the channel in 4 ms lockstep steps to `until_ns`, collecting deliveries.
inline void StepTo(Channel& ch, std::int64_t from_ns, std::int64_t until_ns, std::vector<Delivery>* out) {
  for (std::int64_t t = from_ns; t < until_ns;) {
    t = std::min(until_ns, t + 4'000'000);
    ch.TakeDeliveries(t, out);
  }
}

// Drone 0 sends `frames` frames of `size` bytes to drone 1 (or broadcasts when !unicast), one every
// `period_ns`, from the channel's taken_until_ns() (or 0); then the channel runs on for 2 s.
// Returns the deliveries.
inline std::vector<Delivery> SendStream(Channel& ch, int frames, std::int64_t period_ns, std::uint32_t size = 100,
                                        bool unicast = true) {
  std::vector<Delivery> got;
  const std::int64_t start_ns = std::max<std::int64_t>(0, ch.taken_until_ns());
  std::int64_t t = start_ns;
  for (int i = 0; i < frames; ++i) {
    t = start_ns + static_cast<std::int64_t>(i) * period_ns;
    ch.TakeDeliveries(t, &got);
    Packet p;
    p.from = 0;
    if (unicast) p.to = 1;
    p.seq = static_cast<std::uint64_t>(i);
    p.size_bytes = size;
    p.sent_ns = t;
    p.token = static_cast<std::uint64_t>(i);
    ch.Send(t, p);
  }
  ch.TakeDeliveries(t + 2'000'000'000, &got);
  return got;
}

inline Packet Broadcast(std::size_t from, std::uint64_t seq, std::int64_t sent_ns, std::uint32_t size = 100) {
  Packet p;
  p.from = from;
  p.seq = seq;
  p.size_bytes = size;
  p.sent_ns = sent_ns;
  p.token = from * 1000000 + seq;
  return p;
}

inline bool SameDeliveries(const std::vector<Delivery>& a, const std::vector<Delivery>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].to != b[i].to || a[i].at_ns != b[i].at_ns || a[i].packet.from != b[i].packet.from ||
        a[i].packet.seq != b[i].packet.seq || a[i].packet.token != b[i].packet.token) {
      return false;
    }
  }
  return true;
}

}  // namespace swarmbox::channel::testing
