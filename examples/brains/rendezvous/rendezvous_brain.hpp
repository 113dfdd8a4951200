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

// The ring: P and every member's slot, computed with the same operations in the same order as
// the C brain's rv_place_ring (examples/c_brain/rendezvous.h), so the two agree bit for bit
// (compiled without FMA contraction, -ffp-contract=off). Members in sorted name order, at (x[i],
// y[i]) as read from their `pos` entries:
//   P = (sum of x in index order / N, sum of y / N);
//   dx = x[i] - P.x, dy = y[i] - P.y; member i is centred when dx*dx + dy*dy < kCentredM2 (0.01 m),
//   else its bearing is b_i = atan2(dy, dx), with -pi taken as +pi (so b_i is in (-pi, pi]);
//   rank: the members that are not centred by increasing b_i (equal doubles: by index, i.e. name),
//   then the centred ones by index;
//   a0 = the bearing of rank 0 (0.0 when every member is centred);
//   slot of rank r: a = a0 + 2.0 * pi * r / N (left to right, in doubles),
//   (P.x + radius_m * cos(a), P.y + radius_m * sin(a), altitude_m).
// Each drone keeps its angular order around P, so two drones never swap sides of the ring.
struct Ring {
  double px = 0.0;
  double py = 0.0;
  std::vector<swarmbox::brain::Vec3> slots;  // per member, in the order of x and y
};
inline constexpr double kCentredM2 = 1e-4;  // [m^2]
Ring PlaceRing(const std::vector<double>& x, const std::vector<double>& y, double radius_m,
               double altitude_m);

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
  // One step of each phase (Step runs them in order: a phase that ends hands the step on).
  void StepTakeoff(const swarmbox::brain::Input& in, swarmbox::brain::Output& out);
  void StepVoting(const swarmbox::brain::Input& in, swarmbox::brain::Output& out);  // then the ring
  void StepFlying(const swarmbox::brain::Input& in, swarmbox::brain::Output& out);
  void StepArrived(const swarmbox::brain::Input& in, swarmbox::brain::Output& out);
  void StepHolding(const swarmbox::brain::Input& in, swarmbox::brain::Output& out);
  void StepLanding(const swarmbox::brain::Input& in, swarmbox::brain::Output& out);
  static const char* StatusOf(Phase phase);  // Output::status

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
