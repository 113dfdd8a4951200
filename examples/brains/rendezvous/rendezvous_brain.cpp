#include "rendezvous_brain.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <stdexcept>
#include <string_view>

namespace rendezvous {
namespace {

namespace sb = swarmbox::brain;

std::vector<std::string> Split(std::string_view text) {
  std::vector<std::string> words;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && text[i] == ' ') ++i;
    const std::size_t start = i;
    while (i < text.size() && text[i] != ' ') ++i;
    if (i > start) words.emplace_back(text.substr(start, i - start));
  }
  return words;
}

std::optional<double> Number(const std::string& text) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::vector<std::uint8_t> Bytes(const std::string& text) { return {text.begin(), text.end()}; }

std::string Fixed3(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

}  // namespace

std::optional<Entry> ParseEntry(const std::vector<std::uint8_t>& data) {
  const std::string text(data.begin(), data.end());
  const std::vector<std::string> w = Split(text);
  if (w.size() == 4 && w[0] == "pos") {
    const auto x = Number(w[2]);
    const auto y = Number(w[3]);
    if (!x || !y) return std::nullopt;
    return Entry{Entry::Kind::kPos, w[1], *x, *y};
  }
  if (w.size() == 2 && w[0] == "arrived") return Entry{Entry::Kind::kArrived, w[1], 0.0, 0.0};
  return std::nullopt;
}

std::vector<std::uint8_t> PosEntry(const std::string& name, double x, double y) {
  return Bytes("pos " + name + " " + Fixed3(x) + " " + Fixed3(y));
}

std::vector<std::uint8_t> ArrivedEntry(const std::string& name) { return Bytes("arrived " + name); }

namespace {

constexpr double kPi = std::numbers::pi;

// Where each member stands seen from P: centred (within sqrt(kCentredM2) of P, no bearing: 0.0),
// else its bearing in (-pi, pi].
struct Bearings {
  std::vector<bool> centred;
  std::vector<double> bearing;
};

Bearings BearingsFromCentre(const std::vector<double>& x, const std::vector<double>& y, double px, double py) {
  const std::size_t n = x.size();
  Bearings b{std::vector<bool>(n), std::vector<double>(n)};
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = x[i] - px;
    const double dy = y[i] - py;
    b.centred[i] = dx * dx + dy * dy < kCentredM2;
    double bearing = 0.0;
    if (!b.centred[i]) {
      bearing = std::atan2(dy, dx);
      if (bearing <= -kPi) bearing = kPi;  // (-pi, pi]: atan2(-0.0, -1) is -pi
    }
    b.bearing[i] = bearing;
  }
  return b;
}

// Each member's rank on the ring: how many members come before it.
std::vector<std::size_t> RanksOnRing(const Bearings& b) {
  const std::size_t n = b.centred.size();
  // Whether member j comes before member i on the ring.
  const auto before = [&](std::size_t j, std::size_t i) {
    if (b.centred[j] != b.centred[i]) return static_cast<bool>(b.centred[i]);  // the centred ones last
    if (!b.centred[i] && b.bearing[j] != b.bearing[i]) return b.bearing[j] < b.bearing[i];
    return j < i;  // the same bearing (exactly), or both centred: by name
  };
  std::vector<std::size_t> rank(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      if (j != i && before(j, i)) ++rank[i];
    }
  }
  return rank;
}

}  // namespace

Ring PlaceRing(const std::vector<double>& x, const std::vector<double>& y, double radius_m,
               double altitude_m) {
  const std::size_t n = x.size();
  Ring ring;
  double sx = 0.0;
  double sy = 0.0;
  for (std::size_t i = 0; i < n; ++i) {  // sorted member order: the same sum on every drone
    sx += x[i];
    sy += y[i];
  }
  const double count = static_cast<double>(n);
  ring.px = sx / count;
  ring.py = sy / count;

  const Bearings b = BearingsFromCentre(x, y, ring.px, ring.py);
  const std::vector<std::size_t> rank = RanksOnRing(b);
  double a0 = 0.0;  // the first one's bearing; 0 when every member is centred
  for (std::size_t i = 0; i < n; ++i) {
    if (rank[i] == 0 && !b.centred[i]) a0 = b.bearing[i];
  }
  ring.slots.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double a = a0 + 2.0 * kPi * static_cast<double>(rank[i]) / count;
    ring.slots.push_back({ring.px + radius_m * std::cos(a), ring.py + radius_m * std::sin(a), altitude_m});
  }
  return ring;
}

RendezvousBrain::RendezvousBrain(const sb::Context& ctx)
    : self_(ctx.self),
      members_(ctx.members),
      altitude_m_(ctx.ArgDouble("altitude_m", 10.0)),
      radius_m_(ctx.ArgDouble("radius_m", 6.0)),
      hold_ns_(0) {
  const double hold_s = ctx.ArgDouble("hold_s", 5.0);
  if (altitude_m_ < 1.0) throw std::invalid_argument("altitude_m must be >= 1 m");
  if (radius_m_ < 0.0) throw std::invalid_argument("radius_m must be >= 0 m");
  if (hold_s < 0.0) throw std::invalid_argument("hold_s must be >= 0 s");
  hold_ns_ = std::llround(hold_s * 1e9);
  std::sort(members_.begin(), members_.end());
  members_.erase(std::unique(members_.begin(), members_.end()), members_.end());
  const auto it = std::find(members_.begin(), members_.end(), self_);
  if (it == members_.end()) {
    throw std::invalid_argument("drone \"" + self_ + "\" is not among the " +
                                std::to_string(members_.size()) + " members");
  }
  index_ = static_cast<std::size_t>(it - members_.begin());
}

void RendezvousBrain::Apply(const sb::Entry& entry) {
  const std::optional<Entry> e = ParseEntry(entry.data);
  if (!e || !std::binary_search(members_.begin(), members_.end(), e->name)) return;
  if (e->kind == Entry::Kind::kPos) {
    positions_.emplace(e->name, *e);  // the first one per member counts
  } else {
    arrived_[e->name] = true;
  }
}

bool RendezvousBrain::Airborne(const sb::Input& in) const {
  for (const sb::FlightEvent& ev : in.flight_events) {
    if (ev.name == "hover") return true;
  }
  return in.self.flight_mode == "hold" && in.self.position_m.z > altitude_m_ - 1.0;
}

void RendezvousBrain::ProposeUntil(bool committed, const std::vector<std::uint8_t>& entry,
                                   std::int64_t t_ns, sb::Output& out) {
  if (committed) return;
  if (proposed_ && t_ns - last_proposal_ns_ < kReproposeNs) return;
  out.proposals.push_back(entry);
  proposed_ = true;
  last_proposal_ns_ = t_ns;
}

void RendezvousBrain::SetpointToSlot(sb::Output& out) const {
  out.setpoint.push_back(sb::Setpoint::Position(slot_));
}

void RendezvousBrain::Step(const sb::Input& in, sb::Output& out) {
  for (const sb::Entry& entry : in.committed) Apply(entry);
  // A phase that ends hands the same step to the next one.
  if (phase_ == Phase::kTakeoff) StepTakeoff(in, out);
  if (phase_ == Phase::kVoting) StepVoting(in, out);
  if (phase_ == Phase::kFlying) StepFlying(in, out);
  if (phase_ == Phase::kArrived) StepArrived(in, out);
  if (phase_ == Phase::kHolding) {
    StepHolding(in, out);
  } else if (phase_ == Phase::kLanding) {
    StepLanding(in, out);
  }
  out.status = StatusOf(phase_);
}

void RendezvousBrain::StepTakeoff(const sb::Input& in, sb::Output& out) {
  bool rejected = false;
  for (const sb::FlightEvent& ev : in.flight_events) rejected = rejected || ev.name == "setpoint_rejected";
  // A take-off refused on the ground (the estimator was not ready) is asked again.
  if (rejected && in.self.landed) takeoff_asked_ = false;
  if (!takeoff_asked_ && in.self.landed && in.self.flight_mode != "init") {
    out.commands.push_back(sb::Command::Takeoff(altitude_m_));
    takeoff_asked_ = true;
  } else if (takeoff_asked_ && Airborne(in)) {
    phase_ = Phase::kVoting;
    proposed_ = false;
    pos_entry_ = PosEntry(self_, in.self.position_m.x, in.self.position_m.y);
  }
}

void RendezvousBrain::StepVoting(const sb::Input& in, sb::Output& out) {
  ProposeUntil(positions_.count(self_) > 0, pos_entry_, in.t_ns, out);
  if (positions_.size() != members_.size()) return;
  std::vector<double> x;
  std::vector<double> y;
  for (const std::string& m : members_) {  // sorted order: the same ring on every drone
    x.push_back(positions_.at(m).x);
    y.push_back(positions_.at(m).y);
  }
  const Ring ring = PlaceRing(x, y, radius_m_, altitude_m_);
  slot_ = ring.slots[index_];
  out.events.push_back({"rendezvous_point", {{"x", Fixed3(ring.px)}, {"y", Fixed3(ring.py)}}});
  phase_ = Phase::kFlying;
}

void RendezvousBrain::StepFlying(const sb::Input& in, sb::Output& out) {
  SetpointToSlot(out);
  const double dx = in.self.position_m.x - slot_.x;
  const double dy = in.self.position_m.y - slot_.y;
  if (std::hypot(dx, dy) <= kArrivedM) {
    phase_ = Phase::kArrived;
    proposed_ = false;
  }
}

void RendezvousBrain::StepArrived(const sb::Input& in, sb::Output& out) {
  if (out.setpoint.empty()) SetpointToSlot(out);
  ProposeUntil(arrived_.count(self_) > 0, ArrivedEntry(self_), in.t_ns, out);
  if (arrived_.size() == members_.size()) {
    phase_ = Phase::kHolding;
    land_at_ns_ = in.t_ns + hold_ns_;
  }
}

void RendezvousBrain::StepHolding(const sb::Input& in, sb::Output& out) {
  if (in.t_ns >= land_at_ns_) {
    out.setpoint.clear();  // the land command is the last word
    out.commands.push_back(sb::Command::Land());
    phase_ = Phase::kLanding;
  } else if (out.setpoint.empty()) {
    SetpointToSlot(out);
  }
}

void RendezvousBrain::StepLanding(const sb::Input& in, sb::Output& out) {
  bool landed = in.self.landed;
  for (const sb::FlightEvent& ev : in.flight_events) landed = landed || ev.name == "landed";
  if (landed) {
    out.events.push_back({"rendezvous_complete", {{"members", std::to_string(members_.size())}}});
    phase_ = Phase::kDone;
  }
}

const char* RendezvousBrain::StatusOf(Phase phase) {
  switch (phase) {
    case Phase::kTakeoff: return "rendezvous/takeoff";
    case Phase::kVoting: return "rendezvous/voting";
    case Phase::kFlying: return "rendezvous/flying";
    case Phase::kArrived: return "rendezvous/arrived";
    case Phase::kHolding:
    case Phase::kLanding: return "rendezvous/landing";
    case Phase::kDone: return "rendezvous/done";
  }
  return "rendezvous/done";  // not reached: every phase is listed above
}

}  // namespace rendezvous

SWARMBOX_BRAIN("rendezvous", rendezvous::RendezvousBrain)
