#include "recorder_json.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/record/foxglove_schemas.hpp"

namespace swarmbox::physics {

void JsonOut::Before() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (!first_.empty()) {
    if (!first_.back()) out_ += ',';
    first_.back() = false;
  }
}

JsonOut& JsonOut::Key(std::string_view key) {
  if (!first_.empty()) {
    if (!first_.back()) out_ += ',';
    first_.back() = false;
  }
  out_ += yaml::JsonQuote(key);
  out_ += ':';
  after_key_ = true;
  return *this;
}

JsonOut& JsonOut::Value(std::string_view json) {
  Before();
  out_.append(json);
  return *this;
}

JsonOut& JsonOut::Num(double v) {
  if (!std::isfinite(v)) return Value("null");
  char buf[32];
  const int n = std::snprintf(buf, sizeof buf, "%.9g", v);
  return Value(std::string_view(buf, static_cast<std::size_t>(n)));
}

JsonOut& JsonOut::Int(std::int64_t v) { return Value(std::to_string(v)); }

JsonOut& JsonOut::Str(std::string_view s) { return Value(yaml::JsonQuote(s)); }

JsonOut& JsonOut::Vec(const std::array<double, 3>& v) {
  Open('[');
  for (double x : v) Num(x);
  return Close(']');
}

JsonOut& JsonOut::Open(char c) {
  Before();
  out_ += c;
  first_.push_back(true);
  return *this;
}

JsonOut& JsonOut::Close(char c) {
  out_ += c;
  first_.pop_back();
  return *this;
}

JsonOut& JsonOut::Time(std::uint64_t t_ns) { return Value(record::JsonTimestamp(t_ns)); }

namespace {

std::uint64_t Ns(std::int64_t t_ns) { return t_ns < 0 ? 0 : static_cast<std::uint64_t>(t_ns); }

void Xyz(JsonOut& j, double x, double y, double z) {
  j.Open('{').Key("x").Num(x).Key("y").Num(y).Key("z").Num(z).Close('}');
}
void QuatJson(JsonOut& j, double w, double x, double y, double z) {
  j.Open('{').Key("x").Num(x).Key("y").Num(y).Key("z").Num(z).Key("w").Num(w).Close('}');
}
void ColorJson(JsonOut& j, double r, double g, double b, double a) {
  j.Open('{').Key("r").Num(r).Key("g").Num(g).Key("b").Num(b).Key("a").Num(a).Close('}');
}
void PoseJson(JsonOut& j, double x, double y, double z, double yaw_rad) {
  j.Open('{').Key("position");
  Xyz(j, x, y, z);
  j.Key("orientation");
  QuatJson(j, std::cos(yaw_rad / 2), 0, 0, std::sin(yaw_rad / 2));
  j.Close('}');
}
// One scene entity with a single cube, frame `world`, until replaced.
void CubeEntity(JsonOut& j, std::uint64_t t_ns, std::string_view id, std::string_view kind, double x, double y, double z,
                double yaw_rad, double sx, double sy, double sz, std::array<double, 4> rgba) {
  j.Open('{').Key("timestamp").Time(t_ns).Key("frame_id").Str("world").Key("id").Str(id);
  j.Key("lifetime").Value("{\"sec\":0,\"nsec\":0}").Key("frame_locked").Bool(false);
  j.Key("metadata").Open('[').Open('{').Key("key").Str("kind").Key("value").Str(kind).Close('}').Close(']');
  j.Key("arrows").Open('[').Close(']');
  j.Key("cubes").Open('[').Open('{').Key("pose");
  PoseJson(j, x, y, z, yaw_rad);
  j.Key("size");
  Xyz(j, sx, sy, sz);
  j.Key("color");
  ColorJson(j, rgba[0], rgba[1], rgba[2], rgba[3]);
  j.Close('}').Close(']');
  j.Key("spheres").Open('[').Close(']').Key("cylinders").Open('[').Close(']');
  j.Key("lines").Open('[').Close(']').Key("texts").Open('[').Close(']');
  j.Close('}');
}

bool AllFinite(const std::array<double, 3>& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

}  // namespace

std::string WorldSceneJson(std::uint64_t t_ns, const WorldConfig& world) {
  JsonOut j;
  j.Open('{').Key("deletions").Open('[').Close(']').Key("entities").Open('[');
  constexpr double kGroundThickM = 0.1;
  CubeEntity(j, t_ns, "ground", "ground", 0, 0, -kGroundThickM / 2, 0, world.size_x_m, world.size_y_m, kGroundThickM,
             {0.35, 0.45, 0.3, 1.0});
  for (const ObstacleBox& o : world.obstacles) {
    CubeEntity(j, t_ns, "obstacle/" + o.id, "obstacle", o.center_m.x, o.center_m.y, o.center_m.z, o.yaw_rad, o.size_m.x,
               o.size_m.y, o.size_m.z, {0.55, 0.5, 0.45, 1.0});
  }
  // A victim: a 1.7 m x 0.5 m figure lying along its heading.
  for (const Victim& v : world.victims) {
    CubeEntity(j, t_ns, "victim/" + v.id, "victim", v.x_m, v.y_m, 0.15, v.heading_rad, 1.7, 0.5, 0.3,
               {1.0, 0.4, 0.0, 1.0});
  }
  j.Close(']').Close('}');
  return j.Take();
}

std::string TransformsJson(std::uint64_t t_ns, std::span<const TruthPose> poses) {
  JsonOut j;
  j.Open('{').Key("transforms").Open('[');
  for (const TruthPose& p : poses) {
    j.Open('{').Key("timestamp").Time(t_ns).Key("parent_frame_id").Str("world").Key("child_frame_id").Str(p.drone);
    j.Key("translation");
    Xyz(j, p.position_m[0], p.position_m[1], p.position_m[2]);
    j.Key("rotation");
    QuatJson(j, p.orientation_wxyz[0], p.orientation_wxyz[1], p.orientation_wxyz[2], p.orientation_wxyz[3]);
    j.Close('}');
  }
  j.Close(']').Close('}');
  return j.Take();
}

std::string TruthJson(std::uint64_t t_ns, const TruthPose& p) {
  JsonOut j;
  j.Open('{').Key("timestamp").Time(t_ns).Key("drone").Str(p.drone);
  j.Key("position").Vec(p.position_m).Key("velocity").Vec(p.velocity_m_s).Key("orientation");
  QuatJson(j, p.orientation_wxyz[0], p.orientation_wxyz[1], p.orientation_wxyz[2], p.orientation_wxyz[3]);
  j.Close('}');
  return j.Take();
}

std::string EstimateJson(const bus::Telemetry& t) {
  JsonOut j;
  j.Open('{').Key("timestamp").Time(Ns(t.sim_time_ns)).Key("frame_id").Str("world").Key("pose").Open('{');
  j.Key("position");
  Xyz(j, t.position_enu_m[0], t.position_enu_m[1], t.position_enu_m[2]);
  j.Key("orientation");
  QuatJson(j, t.attitude_wxyz[0], t.attitude_wxyz[1], t.attitude_wxyz[2], t.attitude_wxyz[3]);
  j.Close('}').Close('}');
  return j.Take();
}

std::string SetpointJson(const bus::Telemetry& t) {
  JsonOut j;
  j.Open('{').Key("timestamp").Time(Ns(t.sim_time_ns)).Key("flight_mode").Str(t.flight_mode);
  j.Key("position").Vec(t.setpoint_position_enu_m).Key("velocity").Vec(t.setpoint_velocity_enu_m_s);
  j.Key("yaw").Num(t.setpoint_yaw_rad).Close('}');
  return j.Take();
}

bool HasFlocking(const bus::Telemetry& t) {
  return AllFinite(t.flock_separation) && AllFinite(t.flock_alignment) && AllFinite(t.flock_cohesion) &&
         AllFinite(t.flock_sum);
}

std::string FlockingJson(const bus::Telemetry& t) {
  JsonOut j;
  j.Open('{').Key("timestamp").Time(Ns(t.sim_time_ns));
  j.Key("separation").Vec(t.flock_separation).Key("alignment").Vec(t.flock_alignment);
  j.Key("cohesion").Vec(t.flock_cohesion).Key("sum").Vec(t.flock_sum).Close('}');
  return j.Take();
}

std::string FlockingSceneJson(const bus::Telemetry& t) {
  struct Term {
    const std::array<double, 3>* v;
    std::array<double, 4> rgba;
  };
  const Term terms[] = {{&t.flock_separation, {1, 0.2, 0.2, 1}},
                        {&t.flock_alignment, {0.2, 1, 0.2, 1}},
                        {&t.flock_cohesion, {0.3, 0.5, 1, 1}},
                        {&t.flock_sum, {1, 1, 1, 1}}};
  const std::uint64_t t_ns = Ns(t.sim_time_ns);
  JsonOut j;
  j.Open('{').Key("deletions").Open('[').Close(']').Key("entities").Open('[');
  j.Open('{').Key("timestamp").Time(t_ns).Key("frame_id").Str("world").Key("id").Str("flocking/" + t.drone);
  j.Key("lifetime").Value("{\"sec\":1,\"nsec\":0}").Key("frame_locked").Bool(false);
  j.Key("metadata").Open('[').Open('{').Key("key").Str("drone").Key("value").Str(t.drone).Close('}').Close(']');
  j.Key("arrows").Open('[');
  for (const Term& term : terms) {
    const std::array<double, 3>& v = *term.v;
    const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!std::isfinite(len) || len < 1e-6) continue;
    // The arrow points along +x of its pose: yaw to the vector's heading, pitch to its climb.
    const double yaw = std::atan2(v[1], v[0]);
    const double pitch = -std::asin(std::clamp(v[2] / len, -1.0, 1.0));
    const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2), cp = std::cos(pitch / 2), sp = std::sin(pitch / 2);
    j.Open('{').Key("pose").Open('{').Key("position");
    Xyz(j, t.position_enu_m[0], t.position_enu_m[1], t.position_enu_m[2]);
    j.Key("orientation");
    QuatJson(j, cy * cp, -sy * sp, cy * sp, sy * cp);
    j.Close('}');
    j.Key("shaft_length").Num(len * 0.8).Key("shaft_diameter").Num(0.1);
    j.Key("head_length").Num(len * 0.2).Key("head_diameter").Num(0.25).Key("color");
    ColorJson(j, term.rgba[0], term.rgba[1], term.rgba[2], term.rgba[3]);
    j.Close('}');
  }
  j.Close(']');
  j.Key("cubes").Open('[').Close(']').Key("spheres").Open('[').Close(']').Key("cylinders").Open('[').Close(']');
  j.Key("lines").Open('[').Close(']').Key("texts").Open('[').Close(']');
  j.Close('}').Close(']').Close('}');
  return j.Take();
}

std::string RaftJson(const bus::Telemetry& t) {
  const std::string_view role = t.raft_role == "pre_candidate" ? std::string_view("candidate") : t.raft_role;
  JsonOut j;
  j.Open('{').Key("timestamp").Time(Ns(t.sim_time_ns)).Key("role").Str(role);
  j.Key("term").Int(static_cast<std::int64_t>(t.raft_term)).Key("leader").Str(t.raft_leader);
  j.Key("commit_index").Int(static_cast<std::int64_t>(t.raft_commit_index)).Close('}');
  return j.Take();
}

std::string StatusJson(const bus::Telemetry& t) {
  JsonOut j;
  j.Open('{').Key("timestamp").Time(Ns(t.sim_time_ns)).Key("battery_fraction").Num(t.battery_fraction);
  j.Key("mission_stage").Str(t.mission_stage).Key("armed").Bool(t.armed).Key("landed").Bool(t.landed).Close('}');
  return j.Take();
}

std::string LinksJson(const bus::Telemetry& t) {
  JsonOut j;
  j.Open('{').Key("timestamp").Time(Ns(t.sim_time_ns)).Key("links").Open('[');
  for (const bus::TelemetryLink& l : t.links) {
    j.Open('{').Key("from").Str(t.drone).Key("to").Str(l.peer).Key("loss").Num(l.loss).Key("rtt_ms").Num(l.rtt_ms);
    j.Close('}');
  }
  j.Close(']').Close('}');
  return j.Take();
}

std::string SectorsJson(const bus::Telemetry& t) {
  JsonOut j;
  j.Open('{').Key("timestamp").Time(Ns(t.sim_time_ns)).Key("sectors").Open('[');
  for (const bus::TelemetrySector& s : t.sectors) {
    j.Open('{').Key("drone").Str(s.drone).Key("polygon").Open('[');
    for (std::size_t i = 0; i + 1 < s.polygon_xy_m.size(); i += 2) {
      j.Open('[').Num(s.polygon_xy_m[i]).Num(s.polygon_xy_m[i + 1]).Close(']');
    }
    j.Close(']').Close('}');
  }
  j.Close(']').Close('}');
  return j.Take();
}

std::string DetectionJson(const bus::Detection& d) {
  JsonOut j;
  j.Open('{').Key("timestamp").Time(Ns(d.sim_time_ns)).Key("drone").Str(d.from);
  j.Key("position").Vec(d.position_enu_m).Key("confidence").Num(d.confidence).Close('}');
  return j.Take();
}

int LogLevelOf(std::string_view event) {
  auto has = [&](std::string_view part) { return event.find(part) != std::string_view::npos; };
  auto ends = [&](std::string_view tail) {
    return event.size() >= tail.size() && event.substr(event.size() - tail.size()) == tail;
  };
  if (event == "error" || ends("_error") || ends("_failed") || event == "crashed") return record::kLogError;
  if (has("lost") || has("rejected") || has("missing") || has("stopped") || has("timeout")) return record::kLogWarning;
  return record::kLogInfo;
}

std::string LogJson(std::uint64_t t_ns, std::string_view node, std::string_view event, std::string_view line) {
  JsonOut j;
  j.Open('{').Key("timestamp").Time(t_ns).Key("level").Int(LogLevelOf(event)).Key("message").Str(line);
  j.Key("name").Str(node).Key("file").Str("").Key("line").Int(0).Close('}');
  return j.Take();
}

std::string EventLogJson(const bus::Event& e) {
  LogEvent line(static_cast<double>(e.sim_time_ns) * 1e-9, e.node, e.name);
  for (const bus::KeyValue& kv : e.fields) line.Add(kv.key, kv.value);
  return LogJson(Ns(e.sim_time_ns), e.node, e.name, line.str());
}

std::string Base64(std::span<const std::uint8_t> bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i + 1 == bytes.size()) {
    const std::uint32_t v = std::uint32_t{bytes[i]} << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

std::string CompressedImageJson(std::uint64_t t_ns, std::string_view frame_id, std::span<const std::uint8_t> jpeg) {
  JsonOut j;
  j.Open('{').Key("timestamp").Time(t_ns).Key("frame_id").Str(frame_id).Key("format").Str("jpeg");
  j.Key("data").Value("\"" + Base64(jpeg) + "\"").Close('}');
  return j.Take();
}

}  // namespace swarmbox::physics
