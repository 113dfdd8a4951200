#include "live_scenario.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "swarmbox/record/foxglove_schemas.hpp"

namespace swarmbox::testing {
namespace {

using Vec3 = std::array<double, 3>;
using record::ChannelId;

constexpr double kTakeoffEndS = 8.0;
constexpr double kCruiseZ = 20.0;
constexpr double kScoutSpeed = 5.0;     // [m/s]
constexpr double kLifterLeaveS = 80.0;  // the lifter leaves for victim_1
constexpr double kLifterSpeed = 4.0;
constexpr double kFailoverS = 60.0;     // scout_1 drops out of the Raft group...
constexpr double kNewLeaderS = 62.0;    // ... scout_2 leads term 2

struct Victim {
  const char* id;
  double x, y;
};
constexpr Victim kVictims[] = {{"victim_1", 35.0, 20.0}, {"victim_2", -42.0, 55.0}};
struct Obstacle {
  const char* id;
  const char* kind;
  double x, y, sx, sy;
};
constexpr Obstacle kObstacles[] = {{"rubble_1", "obstacle", -20, -40, 12, 6},
                                   {"shed_1", "obstacle", 60, -60, 8, 10},
                                   {"tree_1", "tree", 10, 70, 5, 5},
                                   {"tree_2", "tree", -70, -10, 6, 6}};

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3f", v);
  return buf;
}
std::string Vec(const Vec3& v) { return "[" + Num(v[0]) + "," + Num(v[1]) + "," + Num(v[2]) + "]"; }
std::string Stamp(double t) {
  const auto ns = static_cast<std::int64_t>(std::llround(t * 1e9));
  return R"("timestamp":{"sec":)" + std::to_string(ns / 1'000'000'000) + R"(,"nsec":)" +
         std::to_string(ns % 1'000'000'000) + "}";
}
std::uint64_t Ns(double t) { return static_cast<std::uint64_t>(std::llround(t * 1e9)); }

std::string Base64(const std::vector<unsigned char>& in) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < in.size(); i += 3) {
    const std::uint32_t n = (std::uint32_t{in[i]} << 16) | (i + 1 < in.size() ? std::uint32_t{in[i + 1]} << 8 : 0u) |
                            (i + 2 < in.size() ? std::uint32_t{in[i + 2]} : 0u);
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += i + 1 < in.size() ? kAlphabet[(n >> 6) & 63] : '=';
    out += i + 2 < in.size() ? kAlphabet[n & 63] : '=';
  }
  return out;
}

Vec3 Start(const std::string& drone) {
  if (drone == "lifter") return {0, -10, 0};
  if (drone == "scout_1") return {0, 0, 0};
  if (drone == "scout_2") return {3, 0, 0};
  return {6, 0, 0};
}

int ScoutIndex(const std::string& drone) { return drone.back() - '1'; }  // scout_1 -> 0

// A scout's sector: a third of the field along x.
std::array<double, 4> Sector(int k) {  // x0, x1, y0, y1
  const double w = 200.0 / 3.0;
  return {-100 + k * w, -100 + (k + 1) * w, -100, 100};
}

// The lawnmower: from above its start to its sector's corner, then lanes 20 m apart along y.
std::vector<Vec3> ScoutPath(const std::string& drone) {
  const auto [x0, x1, y0, y1] = Sector(ScoutIndex(drone));
  const Vec3 s = Start(drone);
  std::vector<Vec3> path = {{s[0], s[1], kCruiseZ}};
  bool up = true;
  for (double x = x0 + 10; x < x1; x += 20) {
    path.push_back({x, up ? y0 + 10 : y1 - 10, kCruiseZ});
    path.push_back({x, up ? y1 - 10 : y0 + 10, kCruiseZ});
    up = !up;
  }
  return path;
}

Vec3 Along(const std::vector<Vec3>& path, double distance) {
  for (std::size_t i = 1; i < path.size(); ++i) {
    const double dx = path[i][0] - path[i - 1][0], dy = path[i][1] - path[i - 1][1];
    const double len = std::hypot(dx, dy);
    if (distance <= len) {
      const double f = len > 0 ? distance / len : 0;
      return {path[i - 1][0] + dx * f, path[i - 1][1] + dy * f, kCruiseZ};
    }
    distance -= len;
  }
  return path.back();
}

double Distance(const Vec3& a, const Vec3& b) { return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]); }


std::string CameraJpeg(const std::string& drone, double t, const Vec3& p) {
  cv::Mat img(120, 160, CV_8UC3, cv::Scalar(60, 110, 80));
  for (int i = 0; i < 12; ++i) {  // ground texture that moves with the drone
    const int x = static_cast<int>(std::fmod(std::fabs(p[0] * 3 + i * 37), 160));
    const int y = static_cast<int>(std::fmod(std::fabs(p[1] * 3 + i * 53), 120));
    cv::circle(img, {x, y}, 6, cv::Scalar(45, 85, 95), cv::FILLED);
  }
  for (const Victim& v : kVictims) {
    const double dx = v.x - p[0], dy = v.y - p[1];
    if (std::hypot(dx, dy) < 15) {
      cv::ellipse(img, {80 + static_cast<int>(dx * 4), 60 - static_cast<int>(dy * 4)}, {10, 4}, 30, 0, 360,
                  cv::Scalar(40, 40, 220), cv::FILLED);
    }
  }
  cv::putText(img, drone, {4, 14}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(255, 255, 255), 1);
  cv::putText(img, "t=" + Num(t).substr(0, Num(t).size() - 2), {4, 112}, cv::FONT_HERSHEY_SIMPLEX, 0.35,
              cv::Scalar(230, 230, 230), 1);
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", img, jpeg, {cv::IMWRITE_JPEG_QUALITY, 75});
  return Base64(jpeg);
}

std::string LogJson(double t, int level, const std::string& node, const std::string& fields) {
  const std::string line = "t=" + Num(t) + " node=" + node + " " + fields;
  std::string escaped;
  for (char c : line) {
    if (c == '"' || c == '\\') escaped += '\\';
    escaped += c;
  }
  return "{" + Stamp(t) + R"(,"level":)" + std::to_string(level) + R"(,"name":")" + node +
         R"(","message":")" + escaped + R"(","file":"","line":0})";
}

std::string WorldJson() {
  auto cube = [](const std::string& id, const std::string& kind, double x, double y, double z, double sx,
                 double sy, double sz, const std::string& color) {
    return R"({"timestamp":{"sec":0,"nsec":0},"frame_id":"world","id":")" + id +
           R"(","lifetime":{"sec":0,"nsec":0},"frame_locked":false,"metadata":[{"key":"kind","value":")" + kind +
           R"("}],"arrows":[],"cubes":[{"pose":{"position":{"x":)" + Num(x) + R"(,"y":)" + Num(y) +
           R"(,"z":)" + Num(z) + R"(},"orientation":{"x":0,"y":0,"z":0,"w":1}},"size":{"x":)" + Num(sx) +
           R"(,"y":)" + Num(sy) + R"(,"z":)" + Num(sz) + R"(},"color":)" + color +
           R"(}],"spheres":[],"cylinders":[],"lines":[],"triangles":[],"texts":[],"models":[]})";
  };
  std::string entities = cube("ground", "ground", 0, 0, -0.05, 200, 200, 0.1, R"({"r":0.3,"g":0.45,"b":0.25,"a":1})");
  for (const Obstacle& o : kObstacles) {
    entities += "," + cube(o.id, o.kind, o.x, o.y, 3, o.sx, o.sy, 6, R"({"r":0.5,"g":0.5,"b":0.55,"a":1})");
  }
  for (const Victim& v : kVictims) {
    entities += "," + cube(v.id, "victim", v.x, v.y, 0.2, 1.8, 0.6, 0.4, R"({"r":0.9,"g":0.1,"b":0.1,"a":1})");
  }
  return "{" + Stamp(0) + R"(,"deletions":[],"entities":[)" + entities + "]}";
}

std::string SectorsJson(double t) {
  std::string s = "{" + Stamp(t) + R"(,"sectors":[)";
  for (int k = 0; k < 3; ++k) {
    const auto [x0, x1, y0, y1] = Sector(k);
    if (k) s += ",";
    s += R"({"drone":"scout_)" + std::to_string(k + 1) + R"(","polygon":[[)" + Num(x0) + "," + Num(y0) + "],[" +
         Num(x1) + "," + Num(y0) + "],[" + Num(x1) + "," + Num(y1) + "],[" + Num(x0) + "," + Num(y1) + "]]}";
  }
  return s + "]}";
}

struct RaftView {
  const char* role;
  int term;
  const char* leader;
};
RaftView Raft(const std::string& drone, double t) {
  if (drone == "lifter") return {"learner", t < kNewLeaderS ? 1 : 2, t < kNewLeaderS ? "scout_1" : "scout_2"};
  if (t < 3.0) return {"follower", 0, ""};
  if (t < kFailoverS) return {drone == "scout_1" ? "leader" : "follower", 1, "scout_1"};
  if (t < kNewLeaderS) {
    return {drone == "scout_1" ? "follower" : drone == "scout_2" ? "candidate" : "follower", drone == "scout_2" ? 2 : 1,
            ""};
  }
  return {drone == "scout_2" ? "leader" : "follower", 2, "scout_2"};
}

}  // namespace

std::array<double, 3> ScenarioPosition(const std::string& drone, double t) {
  const Vec3 s = Start(drone);
  const double cruise = drone == "lifter" ? 15.0 : kCruiseZ;
  if (t < kTakeoffEndS) return {s[0], s[1], cruise * std::clamp(t / kTakeoffEndS, 0.0, 1.0)};
  if (drone == "lifter") {
    if (t < kLifterLeaveS) return {s[0], s[1], cruise};
    const Vec3 target = {kVictims[0].x, kVictims[0].y, cruise};
    const double d = std::hypot(target[0] - s[0], target[1] - s[1]);
    const double f = std::min(1.0, (t - kLifterLeaveS) * kLifterSpeed / d);
    const double arrive = kLifterLeaveS + d / kLifterSpeed;
    const double z = t < arrive ? cruise : std::max(0.0, cruise - (t - arrive) * 1.5);
    return {s[0] + (target[0] - s[0]) * f, s[1] + (target[1] - s[1]) * f, z};
  }
  return Along(ScoutPath(drone), (t - kTakeoffEndS) * kScoutSpeed);
}

Status WriteSarScenario(record::Sink& sink) {
  auto add = [&](const std::string& topic, const std::string& schema) -> Result<ChannelId> {
    return sink.AddChannel(record::MakeChannel(topic, schema));
  };
  std::map<std::string, ChannelId> ch;
  for (const auto& [topic, schema] : std::vector<std::pair<std::string, std::string>>{
           {"/world", "foxglove.SceneUpdate"}, {"/tf", "foxglove.FrameTransforms"},
           {"/radio/links", "swarmbox.Links"}, {"/mission/sectors", "swarmbox.Sectors"},
           {"/detections", "swarmbox.Detection"}, {"/log", "foxglove.Log"}}) {
    auto id = add(topic, schema);
    if (!id) return id.error();
    ch[topic] = *id;
  }
  for (const std::string& d : kScenarioDrones) {
    for (const auto& [leaf, schema] : std::vector<std::pair<std::string, std::string>>{
             {"truth", "swarmbox.DroneTruth"}, {"raft", "swarmbox.RaftState"},
             {"status", "swarmbox.AgentStatus"}, {"camera", "foxglove.CompressedImage"}}) {
      auto id = add("/drones/" + d + "/" + leaf, schema);
      if (!id) return id.error();
      ch["/drones/" + d + "/" + leaf] = *id;
    }
  }
  auto write = [&](const std::string& topic, double t, const std::string& json) {
    return sink.Write(ch.at(topic), Ns(t), json);
  };
  auto log = [&](double t, int level, const std::string& node, const std::string& fields) {
    return write("/log", t, LogJson(t, level, node, fields));
  };

  if (auto s = write("/world", 0, WorldJson()); !s) return s;
  std::map<std::string, bool> sighted;
  const int ticks = static_cast<int>(kScenarioDurationS * 10);
  for (int tick = 0; tick <= ticks; ++tick) {
    const double t = tick / 10.0;
    std::map<std::string, Vec3> pos;
    std::string tf = "{" + Stamp(t) + R"(,"transforms":[)";
    for (const std::string& d : kScenarioDrones) {
      pos[d] = ScenarioPosition(d, t);
      const Vec3 next = ScenarioPosition(d, t + 0.1);
      const Vec3 vel = {(next[0] - pos[d][0]) * 10, (next[1] - pos[d][1]) * 10, (next[2] - pos[d][2]) * 10};
      if (d != kScenarioDrones.front()) tf += ",";
      tf += "{" + Stamp(t) + R"(,"parent_frame_id":"world","child_frame_id":")" + d +
            R"(","translation":{"x":)" + Num(pos[d][0]) + R"(,"y":)" + Num(pos[d][1]) + R"(,"z":)" +
            Num(pos[d][2]) + R"(},"rotation":{"x":0,"y":0,"z":0,"w":1}})";
      if (auto s = write("/drones/" + d + "/truth", t,
                         "{" + Stamp(t) + R"(,"drone":")" + d + R"(","position":)" + Vec(pos[d]) +
                             R"(,"velocity":)" + Vec(vel) + R"(,"orientation":{"x":0,"y":0,"z":0,"w":1}})");
          !s) {
        return s;
      }
    }
    if (auto s = write("/tf", t, tf + "]}"); !s) return s;

    if (tick % 10 == 0) {  // 1 Hz: status, Raft, camera
      for (const std::string& d : kScenarioDrones) {
        const RaftView r = Raft(d, t);
        const char* stage = t < kTakeoffEndS ? "takeoff" : d == "lifter" ? (t < kLifterLeaveS ? "standby" : "deliver") : "search";
        if (auto s = write("/drones/" + d + "/status", t,
                           "{" + Stamp(t) + R"(,"battery_fraction":)" + Num(1.0 - t / 600.0) +
                               R"(,"mission_stage":")" + stage + R"(","armed":true,"landed":)" +
                               (pos[d][2] < 0.2 ? "true" : "false") + "}");
            !s) {
          return s;
        }
        if (auto s = write("/drones/" + d + "/raft", t,
                           "{" + Stamp(t) + R"(,"role":")" + r.role + R"(","term":)" + std::to_string(r.term) +
                               R"(,"leader":")" + r.leader + R"(","commit_index":)" +
                               std::to_string(static_cast<int>(t * 2)) + "}");
            !s) {
          return s;
        }
        if (auto s = write("/drones/" + d + "/camera", t,
                           "{" + Stamp(t) + R"(,"frame_id":")" + d + R"(_camera","format":"jpeg","data":")" +
                               CameraJpeg(d, t, pos[d]) + R"("})");
            !s) {
          return s;
        }
      }
    }
    if (tick % 5 == 0) {  // 2 Hz: the links each agent measured, one message per agent (as the recorder)
      for (const std::string& a : kScenarioDrones) {
        std::string links = "{" + Stamp(t) + R"(,"links":[)";
        bool first = true;
        for (const std::string& b : kScenarioDrones) {
          if (a == b) continue;
          const double dist = Distance(pos[a], pos[b]);
          const bool cut = t >= kFailoverS && t < kNewLeaderS && (a == "scout_1" || b == "scout_1");
          const double loss = cut ? 1.0 : std::min(0.9, 0.02 + (dist / 250) * (dist / 250));
          if (!first) links += ",";
          first = false;
          links += R"({"from":")" + a + R"(","to":")" + b + R"(","loss":)" + Num(loss) + R"(,"rtt_ms":)" +
                   Num(200 + dist) + "}";
        }
        if (auto s = write("/radio/links", t, links + "]}"); !s) return s;
      }
    }
    for (const std::string& d : kScenarioDrones) {
      if (d == "lifter" || tick % 5 != 0) continue;
      for (const Victim& v : kVictims) {
        const double dist = std::hypot(pos[d][0] - v.x, pos[d][1] - v.y);
        if (dist > 12) continue;
        const double conf = 0.9 - dist / 30;
        if (auto s = write("/detections", t,
                           "{" + Stamp(t) + R"(,"drone":")" + d + R"(","position":)" +
                               Vec({v.x + 0.8, v.y - 0.5, 0}) + R"(,"confidence":)" + Num(conf) + "}");
            !s) {
          return s;
        }
        if (!sighted[v.id]) {
          sighted[v.id] = true;
          if (auto s = log(t, 2, d, std::string("event=sighting victim=") + v.id + " confidence=" + Num(conf)); !s) {
            return s;
          }
        }
      }
    }
    // Events at their times.
    if (tick == 10) {
      for (const std::string& d : kScenarioDrones) {
        if (auto s = log(t, 2, d, "event=takeoff"); !s) return s;
      }
    }
    if (tick == 30) {
      if (auto s = log(t, 2, "scout_1", "event=leader_elected term=1 leader=scout_1"); !s) return s;
    }
    if (tick == 80) {
      if (auto s = write("/mission/sectors", t, SectorsJson(t)); !s) return s;
      if (auto s = log(t, 2, "scout_1", "event=sectors_assigned count=3"); !s) return s;
    }
    if (tick == static_cast<int>(kFailoverS * 10)) {
      if (auto s = log(t, 3, "scout_2", "event=election_timeout term=1 last_leader=scout_1"); !s) return s;
    }
    if (tick == static_cast<int>(kNewLeaderS * 10)) {
      if (auto s = log(t, 2, "scout_2", "event=leader_elected term=2 leader=scout_2"); !s) return s;
    }
    if (tick == static_cast<int>(kNewLeaderS * 10) + 10) {
      if (auto s = write("/mission/sectors", t, SectorsJson(t)); !s) return s;
      if (auto s = log(t, 2, "scout_2", "event=sectors_assigned count=3"); !s) return s;
    }
    if (tick == static_cast<int>(kLifterLeaveS * 10)) {
      if (auto s = log(t, 2, "lifter", "event=deliver victim=victim_1"); !s) return s;
    }
  }
  return Ok{};
}

}  // namespace swarmbox::testing
