#include "brain_convert.hpp"

#include <array>
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

bus::Event EventToBus(const std::string& node, std::int64_t t_ns, const std::string& name,
                      const std::map<std::string, std::string>& fields) {
  bus::Event e;
  e.node = node;
  e.sim_time_ns = t_ns;
  e.name = name;
  for (const auto& [k, v] : fields) e.fields.push_back({k, v});
  return e;
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
  n.name = s.drone;
  n.t_ns = s.sim_time_ns;
  n.position_m = V(s.position_enu_m);
  n.velocity_m_s = V(s.velocity_enu_m_s);
  n.heading_rad = s.heading_rad;
  n.battery_fraction = s.battery_fraction;
  n.status = s.mode;
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
  out.t_ns = d.sim_time_ns;
  out.label = d.label;
  out.confidence = d.confidence;
  out.position_m = V(d.position_enu_m);
  out.sigma_m = d.position_sigma_m;
  return out;
}

bus::Detection DetectionToBus(const brain::Detection& d, const std::string& from) {
  bus::Detection out;
  out.from = from;
  out.sim_time_ns = d.t_ns;
  out.label = d.label;
  out.confidence = d.confidence;
  out.position_enu_m = A(d.position_m);
  out.position_sigma_m = d.sigma_m;
  return out;
}

bus::VehicleState VehicleToBus(const brain::Vehicle& v, std::int64_t t_ns) {
  bus::VehicleState s;
  s.drone = v.name;
  s.step = v.step;
  s.sim_time_ns = t_ns;
  s.position_enu_m = A(v.position_m);
  s.velocity_enu_m_s = A(v.velocity_m_s);
  for (int i = 0; i < 4; ++i) s.attitude_wxyz[static_cast<std::size_t>(i)] = v.attitude_wxyz[i];
  s.angular_rate_flu_rad_s = A(v.angular_rate_rad_s);
  s.battery_fraction = v.battery_fraction;
  s.battery_voltage_v = v.battery_voltage_v;
  s.flight_mode = v.flight_mode;
  s.armed = v.armed;
  s.landed = v.landed;
  s.payload_mass_kg = v.payload_mass_kg;
  s.mass_estimate_kg = v.mass_estimate_kg;
  return s;
}

brain::Vehicle VehicleFromBus(const bus::VehicleState& s) {
  brain::Vehicle v;
  v.name = s.drone;
  v.step = s.step;
  v.position_m = V(s.position_enu_m);
  v.velocity_m_s = V(s.velocity_enu_m_s);
  for (int i = 0; i < 4; ++i) v.attitude_wxyz[i] = s.attitude_wxyz[static_cast<std::size_t>(i)];
  v.angular_rate_rad_s = V(s.angular_rate_flu_rad_s);
  // The heading is not on the wire: yaw of the (w, x, y, z) attitude, ENU.
  const double w = v.attitude_wxyz[0], x = v.attitude_wxyz[1], y = v.attitude_wxyz[2], z = v.attitude_wxyz[3];
  v.heading_rad = std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
  v.battery_fraction = s.battery_fraction;
  v.battery_voltage_v = s.battery_voltage_v;
  v.flight_mode = s.flight_mode;
  v.armed = s.armed;
  v.landed = s.landed;
  v.payload_mass_kg = s.payload_mass_kg;
  v.mass_estimate_kg = s.mass_estimate_kg;
  return v;
}

bus::TrajectorySetpoint SetpointToBus(const brain::Setpoint& sp) {
  bus::TrajectorySetpoint t;
  t.position_enu_m = A(sp.position_m);
  t.velocity_enu_m_s = A(sp.velocity_m_s);
  t.acceleration_enu_m_s2 = A(sp.acceleration_m_s2);
  t.yaw_rad = sp.yaw_rad;
  t.yawspeed_rad_s = sp.yawspeed_rad_s;
  return t;
}

brain::Setpoint SetpointFromBus(const bus::TrajectorySetpoint& t) {
  brain::Setpoint sp;
  sp.position_m = V(t.position_enu_m);
  sp.velocity_m_s = V(t.velocity_enu_m_s);
  sp.acceleration_m_s2 = V(t.acceleration_enu_m_s2);
  sp.yaw_rad = t.yaw_rad;
  sp.yawspeed_rad_s = t.yawspeed_rad_s;
  return sp;
}

void ToBus(const brain::Input& in, const std::string& drone, bus::BrainInput* out) {
  out->drone = drone;
  out->sim_time_ns = in.t_ns;
  out->vehicle = VehicleToBus(in.self, in.t_ns);
  out->flight_events.clear();
  for (const brain::FlightEvent& e : in.flight_events) {
    out->flight_events.push_back(EventToBus(drone, e.t_ns, e.name, e.fields));
  }
  out->is_leader = in.is_leader;
  out->leader = in.leader;
  out->neighbours.clear();
  for (const brain::Neighbour& n : in.neighbours) {
    bus::DroneState s;
    s.drone = n.name;
    s.sim_time_ns = n.t_ns;
    s.position_enu_m = A(n.position_m);
    s.velocity_enu_m_s = A(n.velocity_m_s);
    s.heading_rad = n.heading_rad;
    s.battery_fraction = n.battery_fraction;
    s.mode = n.status;
    out->neighbours.push_back(std::move(s));
  }
  out->messages.clear();
  for (const brain::Message& m : in.messages) out->messages.push_back(MessageToBus(m));
  out->committed.clear();
  for (const brain::Entry& e : in.committed) out->committed.push_back({e.index, e.data});
  out->detections.clear();
  for (const brain::Detection& d : in.detections) out->detections.push_back(DetectionToBus(d, drone));
}

void FromBus(const bus::BrainInput& in, InputBuffers* out) {
  out->flight_events.clear();
  for (const bus::Event& e : in.flight_events) {
    brain::FlightEvent f;
    f.name = e.name;
    f.t_ns = e.sim_time_ns;
    for (const bus::KeyValue& kv : e.fields) f.fields[kv.key] = kv.value;
    out->flight_events.push_back(std::move(f));
  }
  out->neighbours.clear();
  for (const bus::DroneState& s : in.neighbours) out->neighbours.push_back(NeighbourFromBus(s));
  out->messages.clear();
  for (const bus::BrainMessage& m : in.messages) out->messages.push_back(MessageFromBus(m));
  out->committed.clear();
  for (const bus::CommittedEntry& e : in.committed) out->committed.push_back({e.index, e.data});
  out->detections.clear();
  for (const bus::Detection& d : in.detections) out->detections.push_back(DetectionFromBus(d));
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
  wire->setpoint.clear();
  for (const brain::Setpoint& sp : out.setpoint) wire->setpoint.push_back(SetpointToBus(sp));
  wire->commands.clear();
  for (const brain::Command& c : out.commands) wire->commands.push_back({brain::CommandName(c.kind), c.param});
  wire->messages.clear();
  for (const brain::Message& m : out.messages) wire->messages.push_back(MessageToBus(m));
  wire->proposals.clear();
  for (const std::vector<std::uint8_t>& p : out.proposals) wire->proposals.push_back({p});
  wire->status = out.status;
  wire->events.clear();
  for (const brain::Event& e : out.events) {
    bus::Event b;
    b.node = drone;
    b.sim_time_ns = t_ns;
    b.name = e.name;
    for (const auto& [k, v] : e.fields) b.fields.push_back({k, v});
    wire->events.push_back(std::move(b));
  }
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
