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

sb::Vec3 Slot(double px, double py, double radius_m, double altitude_m, std::size_t index,
              std::size_t count) {
  // Written as the C brain computes it: 2.0 * pi * i / N, left to right, in doubles.
  const double a = 2.0 * std::numbers::pi * static_cast<double>(index) / static_cast<double>(count);
  return {px + radius_m * std::cos(a), py + radius_m * std::sin(a), altitude_m};
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

  if (phase_ == Phase::kTakeoff) {
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
  if (phase_ == Phase::kVoting) {
    ProposeUntil(positions_.count(self_) > 0, pos_entry_, in.t_ns, out);
    if (positions_.size() == members_.size()) {
      double sx = 0.0;
      double sy = 0.0;
      for (const std::string& m : members_) {  // sorted order: the same sum on every drone
        sx += positions_.at(m).x;
        sy += positions_.at(m).y;
      }
      const double n = static_cast<double>(members_.size());
      const double px = sx / n;
      const double py = sy / n;
      slot_ = Slot(px, py, radius_m_, altitude_m_, index_, members_.size());
      out.events.push_back({"rendezvous_point", {{"x", Fixed3(px)}, {"y", Fixed3(py)}}});
      phase_ = Phase::kFlying;
    }
  }
  if (phase_ == Phase::kFlying) {
    SetpointToSlot(out);
    const double dx = in.self.position_m.x - slot_.x;
    const double dy = in.self.position_m.y - slot_.y;
    if (std::hypot(dx, dy) <= kArrivedM) {
      phase_ = Phase::kArrived;
      proposed_ = false;
    }
  }
  if (phase_ == Phase::kArrived) {
    if (out.setpoint.empty()) SetpointToSlot(out);
    ProposeUntil(arrived_.count(self_) > 0, ArrivedEntry(self_), in.t_ns, out);
    if (arrived_.size() == members_.size()) {
      phase_ = Phase::kHolding;
      land_at_ns_ = in.t_ns + hold_ns_;
    }
  }
  if (phase_ == Phase::kHolding) {
    if (in.t_ns >= land_at_ns_) {
      out.setpoint.clear();  // the land command is the last word
      out.commands.push_back(sb::Command::Land());
      phase_ = Phase::kLanding;
    } else if (out.setpoint.empty()) {
      SetpointToSlot(out);
    }
  } else if (phase_ == Phase::kLanding) {
    bool landed = in.self.landed;
    for (const sb::FlightEvent& ev : in.flight_events) landed = landed || ev.name == "landed";
    if (landed) {
      out.events.push_back({"rendezvous_complete", {{"members", std::to_string(members_.size())}}});
      phase_ = Phase::kDone;
    }
  }

  switch (phase_) {
    case Phase::kTakeoff: out.status = "rendezvous/takeoff"; break;
    case Phase::kVoting: out.status = "rendezvous/voting"; break;
    case Phase::kFlying: out.status = "rendezvous/flying"; break;
    case Phase::kArrived: out.status = "rendezvous/arrived"; break;
    case Phase::kHolding:
    case Phase::kLanding: out.status = "rendezvous/landing"; break;
    case Phase::kDone: out.status = "rendezvous/done"; break;
  }
}

}  // namespace rendezvous

SWARMBOX_BRAIN("rendezvous", rendezvous::RendezvousBrain)
