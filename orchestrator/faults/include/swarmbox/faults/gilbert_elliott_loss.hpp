// GilbertElliottLoss: netem's bursty loss model ("loss gemodel p r 1-h 1-k") as a pure, seeded
// state machine, for the userspace mechanism: swarmbox-netemd drops (NF_DROP) every queued packet
// it says is lost. Two states, good and bad; per packet, as netem's loss_gilb_ell() does, the state
// may change (good -> bad with p, bad -> good with r) and the packet is lost with the loss
// probability of the state it was in (loss_good, loss_bad).
//
//   GilbertElliottLoss ge({.p = 0.02, .r = 0.25, .loss_bad = 0.9, .loss_good = 0.0}, /*seed=*/7);
//   if (ge.Lose()) drop(packet); else admit(packet);
//
// In the long run the bad state holds p / (p + r) of the packets (bad spells last 1 / r packets on
// average), so the loss rate is (r loss_good + p loss_bad) / (p + r): StationaryLoss().
// Not thread-safe; the daemon's loop owns it. No allocation.
#pragma once

#include <cstdint>
#include <random>

#include "swarmbox/faults/netem_spec.hpp"

namespace swarmbox::faults {

class GilbertElliottLoss {
 public:
  GilbertElliottLoss(const GilbertElliott& model, std::uint64_t seed);
  // One packet: true = lose it.
  bool Lose();
  bool bad() const { return bad_; }
  const GilbertElliott& model() const { return model_; }

 private:
  bool Chance(double probability);
  GilbertElliott model_;
  std::mt19937_64 rng_;
  bool bad_ = false;  // netem starts in the good state
};

// The long-run fraction of packets lost; loss_good when p = r = 0 (never leaves the good state).
double StationaryLoss(const GilbertElliott& model);

}  // namespace swarmbox::faults
