// The rendezvous brain: the brain SDK's worked example (examples/brains/README.md has the protocol).
//
// Each drone takes off, proposes its position to the swarm's consensus log, and once every
// member's position is committed, all of them compute the same rendezvous point (the mean) and fly
// to their own slot on a ring around it; when every member's arrival is committed they hold, then
// land. The same protocol runs as a plain C program over the offboard topics
// (examples/c_brain/): the two kinds of brain fly together in one trial, hence the exact text
// formats and the fixed order of the arithmetic.
//
// Arguments (Context::args, the trial's brain.args): altitude_m (10), radius_m (6), hold_s (5).
// A bad value (not a number, altitude_m < 1, radius_m < 0, hold_s < 0), no members or a drone
// that is not among them: the constructor throws std::invalid_argument (the agent exits 2 with it).
//
// Deterministic: simulated time only (Input::t_ns), no randomness, every decision on committed
// entries, which every drone sees in the same order.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/brain/brain.hpp"

namespace rendezvous {

// One committed entry of the protocol (ASCII): `pos <name> <x> <y>` or `arrived <name>`.
struct Entry {
  enum class Kind : std::uint8_t { kPos, kArrived };
  Kind kind = Kind::kPos;
  std::string name;
  double x = 0.0;
  double y = 0.0;
};
// nullopt for anything else (another brain's entry, a malformed one).
std::optional<Entry> ParseEntry(const std::vector<std::uint8_t>& data);
std::vector<std::uint8_t> PosEntry(const std::string& name, double x, double y);  // "%.3f"
std::vector<std::uint8_t> ArrivedEntry(const std::string& name);

// Slot `index` of `count` on the ring of `radius_m` around (px, py): angle 2*pi*index/count.
swarmbox::brain::Vec3 Slot(double px, double py, double radius_m, double altitude_m,
                           std::size_t index, std::size_t count);

class RendezvousBrain final : public swarmbox::brain::Brain {
 public:
  static constexpr std::int64_t kReproposeNs = 2'000'000'000;  // re-propose every 2 s (simulated)
  static constexpr double kArrivedM = 1.0;                     // horizontal distance to the slot

  explicit RendezvousBrain(const swarmbox::brain::Context& ctx);
  void Step(const swarmbox::brain::Input& in, swarmbox::brain::Output& out) override;

 private:
  enum class Phase : std::uint8_t { kTakeoff, kVoting, kFlying, kArrived, kHolding, kLanding, kDone };

  void Apply(const swarmbox::brain::Entry& entry);
  bool Airborne(const swarmbox::brain::Input& in) const;
  // Proposes `entry` now and every kReproposeNs until `committed`.
  void ProposeUntil(bool committed, const std::vector<std::uint8_t>& entry, std::int64_t t_ns,
                    swarmbox::brain::Output& out);
  void SetpointToSlot(swarmbox::brain::Output& out) const;

  std::string self_;
  std::vector<std::string> members_;  // sorted
  std::size_t index_ = 0;             // self_ in members_
  double altitude_m_;
  double radius_m_;
  std::int64_t hold_ns_;

  Phase phase_ = Phase::kTakeoff;
  bool takeoff_asked_ = false;
  std::map<std::string, Entry> positions_;  // first committed `pos` per member
  std::map<std::string, bool> arrived_;     // committed `arrived` per member
  std::int64_t last_proposal_ns_ = 0;
  bool proposed_ = false;                   // in this phase
  std::vector<std::uint8_t> pos_entry_;     // what this drone proposes while voting
  swarmbox::brain::Vec3 slot_;
  std::int64_t land_at_ns_ = 0;
};

}  // namespace rendezvous
