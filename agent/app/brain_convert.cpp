#include "brain_convert.hpp"

#include <algorithm>
#include <array>
#include <iterator>
#include <cmath>
#include <map>
#include <utility>

namespace swarmbox::agent {
namespace {

constexpr std::array<brain::Command::Kind, 7> kCommandKinds = {
    brain::Command::Kind::kArm,  brain::Command::Kind::kDisarm,        brain::Command::Kind::kTakeoff,
    brain::Command::Kind::kLand, brain::Command::Kind::kHold,          brain::Command::Kind::kPayloadAttach,
    brain::Command::Kind::kPayloadRelease,
};

std::array<double, 3> A(const brain::Vec3& v) { return {v.x, v.y, v.z}; }
brain::Vec3 V(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

// The field lists below pair each brain field with its wire field once (brain first); ToWire
// walks them brain -> bus, FromWire bus -> brain, so both directions convert the same fields.
struct ToWire {
  void operator()(const brain::Vec3& from, std::array<double, 3>& to) const { to = A(from); }
  void operator()(const double (&from)[4], std::array<double, 4>& to) const {
    std::copy(std::begin(from), std::end(from), to.begin());
  }
  template <typename T>
  void operator()(const T& from, T& to) const {
    to = from;
  }
};
struct FromWire {
  void operator()(brain::Vec3& to, const std::array<double, 3>& from) const { to = V(from); }
  void operator()(double (&to)[4], const std::array<double, 4>& from) const {
    std::copy(from.begin(), from.end(), std::begin(to));
  }
  template <typename T>
  void operator()(T& to, const T& from) const {
    to = from;
  }
};

template <typename Vehicle, typename State, typename Copy>
void VehicleFields(Vehicle& v, State& s, const Copy& copy) {
  copy(v.name, s.drone);
  copy(v.step, s.step);
  copy(v.position_m, s.position_enu_m);
  copy(v.velocity_m_s, s.velocity_enu_m_s);
  copy(v.attitude_wxyz, s.attitude_wxyz);
  copy(v.angular_rate_rad_s, s.angular_rate_flu_rad_s);
  copy(v.battery_fraction, s.battery_fraction);
  copy(v.battery_voltage_v, s.battery_voltage_v);
  copy(v.flight_mode, s.flight_mode);
  copy(v.armed, s.armed);
  copy(v.landed, s.landed);
  copy(v.payload_mass_kg, s.payload_mass_kg);
  copy(v.mass_estimate_kg, s.mass_estimate_kg);
}

template <typename Setpoint, typename Trajectory, typename Copy>
void SetpointFields(Setpoint& sp, Trajectory& t, const Copy& copy) {
  copy(sp.position_m, t.position_enu_m);
  copy(sp.velocity_m_s, t.velocity_enu_m_s);
  copy(sp.acceleration_m_s2, t.acceleration_enu_m_s2);
  copy(sp.yaw_rad, t.yaw_rad);
  copy(sp.yawspeed_rad_s, t.yawspeed_rad_s);
}

template <typename Neighbour, typename State, typename Copy>
void NeighbourFields(Neighbour& n, State& s, const Copy& copy) {
  copy(n.name, s.drone);
  copy(n.t_ns, s.sim_time_ns);
  copy(n.position_m, s.position_enu_m);
  copy(n.velocity_m_s, s.velocity_enu_m_s);
  copy(n.heading_rad, s.heading_rad);
  copy(n.battery_fraction, s.battery_fraction);
  copy(n.status, s.mode);
}

template <typename Detection, typename Wire, typename Copy>
void DetectionFields(Detection& d, Wire& w, const Copy& copy) {
  copy(d.t_ns, w.sim_time_ns);
  copy(d.label, w.label);
  copy(d.confidence, w.confidence);
  copy(d.position_m, w.position_enu_m);
  copy(d.sigma_m, w.position_sigma_m);
}

// `fields`: a brain::FlightEvent's map or a brain::Event's list of pairs.
template <typename Fields>
bus::Event EventToBus(const std::string& node, std::int64_t t_ns, const std::string& name, const Fields& fields) {
  bus::Event e;
  e.node = node;
  e.sim_time_ns = t_ns;
  e.name = name;
  for (const auto& [k, v] : fields) e.fields.push_back({k, v});
  return e;
}

// `to` cleared, then each element of `from` converted into it, in order.
template <typename From, typename To, typename Convert>
void ConvertAll(const From& from, To* to, const Convert& convert) {
  to->clear();
  for (const auto& x : from) to->push_back(convert(x));
}

bus::DroneState NeighbourToBus(const brain::Neighbour& n) {
  bus::DroneState s;
  NeighbourFields(n, s, ToWire{});
  return s;
}

}  // namespace

Result<brain::Command::Kind> ParseCommandName(std::string_view name) {
  std::string known;
  for (brain::Command::Kind kind : kCommandKinds) {
    const std::string_view text = brain::CommandName(kind);
    if (text == name) return kind;
    known += (known.empty() ? "" : ", ") + std::string(text);
  }
  return Error(ErrorCode::kInvalidArgument, "unknown command '" + std::string(name) + "' (known: " + known + ")");
}

brain::Neighbour NeighbourFromBus(const bus::DroneState& s) {
  brain::Neighbour n;
  NeighbourFields(n, s, FromWire{});
  return n;
}

brain::Message MessageFromBus(const bus::BrainMessage& m) { return {m.from, m.to, m.topic, m.payload}; }

bus::BrainMessage MessageToBus(const brain::Message& m) {
  bus::BrainMessage b;
  b.from = m.from;
  b.to = m.to;
  b.topic = m.topic;
  b.payload = m.payload;
  return b;
}

brain::Detection DetectionFromBus(const bus::Detection& d) {
  brain::Detection out;
  DetectionFields(out, d, FromWire{});
  return out;
}

bus::Detection DetectionToBus(const brain::Detection& d, const std::string& from) {
  bus::Detection out;
  out.from = from;
  DetectionFields(d, out, ToWire{});
  return out;
}

bus::VehicleState VehicleToBus(const brain::Vehicle& v, std::int64_t t_ns) {
  bus::VehicleState s;
  s.drone = v.name;
  s.step = v.step;
  VehicleFields(v, s, ToWire{});
  s.sim_time_ns = t_ns;
  return s;
}

brain::Vehicle VehicleFromBus(const bus::VehicleState& s) {
  brain::Vehicle v;
  VehicleFields(v, s, FromWire{});
  // The heading is not on the wire: yaw of the (w, x, y, z) attitude, ENU.
  const double w = v.attitude_wxyz[0], x = v.attitude_wxyz[1], y = v.attitude_wxyz[2], z = v.attitude_wxyz[3];
  v.heading_rad = std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
  return v;
}

bus::TrajectorySetpoint SetpointToBus(const brain::Setpoint& sp) {
  bus::TrajectorySetpoint t;
  SetpointFields(sp, t, ToWire{});
  return t;
}

brain::Setpoint SetpointFromBus(const bus::TrajectorySetpoint& t) {
  brain::Setpoint sp;
  SetpointFields(sp, t, FromWire{});
  return sp;
}

void ToBus(const brain::Input& in, const std::string& drone, bus::BrainInput* out) {
  out->drone = drone;
  out->sim_time_ns = in.t_ns;
  out->vehicle = VehicleToBus(in.self, in.t_ns);
  ConvertAll(in.flight_events, &out->flight_events,
             [&drone](const brain::FlightEvent& e) { return EventToBus(drone, e.t_ns, e.name, e.fields); });
  out->is_leader = in.is_leader;
  out->leader = in.leader;
  ConvertAll(in.neighbours, &out->neighbours, NeighbourToBus);
  ConvertAll(in.messages, &out->messages, MessageToBus);
  ConvertAll(in.committed, &out->committed, [](const brain::Entry& e) {
    return bus::CommittedEntry{e.index, e.data};
  });
  ConvertAll(in.detections, &out->detections,
             [&drone](const brain::Detection& d) { return DetectionToBus(d, drone); });
}

void FromBus(const bus::BrainInput& in, InputBuffers* out) {
  ConvertAll(in.flight_events, &out->flight_events, [](const bus::Event& e) {
    brain::FlightEvent f;
    f.name = e.name;
    f.t_ns = e.sim_time_ns;
    for (const bus::KeyValue& kv : e.fields) f.fields[kv.key] = kv.value;
    return f;
  });
  ConvertAll(in.neighbours, &out->neighbours, NeighbourFromBus);
  ConvertAll(in.messages, &out->messages, MessageFromBus);
  ConvertAll(in.committed, &out->committed, [](const bus::CommittedEntry& e) {
    return brain::Entry{e.index, e.data};
  });
  ConvertAll(in.detections, &out->detections, DetectionFromBus);
  brain::Input& i = out->input;
  i = brain::Input{};
  i.t_ns = in.sim_time_ns;
  i.self = VehicleFromBus(in.vehicle);
  i.flight_events = out->flight_events;
  i.is_leader = in.is_leader;
  i.leader = in.leader;
  i.neighbours = out->neighbours;
  i.messages = out->messages;
  i.committed = out->committed;
  i.detections = out->detections;
}

void ToBus(const brain::Output& out, const std::string& drone, std::int64_t t_ns, bus::BrainOutput* wire) {
  wire->drone = drone;
  wire->sim_time_ns = t_ns;
  ConvertAll(out.setpoint, &wire->setpoint, SetpointToBus);
  ConvertAll(out.commands, &wire->commands, [](const brain::Command& c) {
    return bus::VehicleCommand{std::string(brain::CommandName(c.kind)), c.param};
  });
  ConvertAll(out.messages, &wire->messages, MessageToBus);
  ConvertAll(out.proposals, &wire->proposals,
             [](const std::vector<std::uint8_t>& p) { return bus::Proposal{p}; });
  wire->status = out.status;
  ConvertAll(out.events, &wire->events,
             [&drone, t_ns](const brain::Event& e) { return EventToBus(drone, t_ns, e.name, e.fields); });
}

Status FromBus(const bus::BrainOutput& wire, brain::Output* out) {
  *out = brain::Output{};
  if (wire.setpoint.size() > 1) {
    return Error(ErrorCode::kInvalidArgument,
                 "a BrainOutput holds at most one setpoint (got " + std::to_string(wire.setpoint.size()) + ")");
  }
  for (const bus::TrajectorySetpoint& t : wire.setpoint) out->setpoint.push_back(SetpointFromBus(t));
  for (const bus::VehicleCommand& c : wire.commands) {
    auto kind = ParseCommandName(c.command);
    if (!kind) return kind.error();
    out->commands.push_back({*kind, c.param});
  }
  for (const bus::BrainMessage& m : wire.messages) out->messages.push_back(MessageFromBus(m));
  for (const bus::Proposal& p : wire.proposals) out->proposals.push_back(p.data);
  out->status = wire.status;
  for (const bus::Event& e : wire.events) {
    brain::Event b;
    b.name = e.name;
    for (const bus::KeyValue& kv : e.fields) b.fields.emplace_back(kv.key, kv.value);
    out->events.push_back(std::move(b));
  }
  return Ok{};
}

}  // namespace swarmbox::agent
