#include "server_options.hpp"

#include <array>
#include <cstdlib>
#include <sstream>

namespace swarmbox::physics {
namespace {

std::vector<std::string> Split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  std::istringstream in(s);
  while (std::getline(in, cur, sep)) out.push_back(cur);
  if (!s.empty() && s.back() == sep) out.emplace_back();
  return out;
}

bool ToDouble(const std::string& s, double* out) {
  if (s.empty()) return false;
  char* end = nullptr;
  *out = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

}  // namespace

Result<DroneSpec> ParseDroneArg(const std::string& text) {
  auto bad = [&](const std::string& why) {
    return Error(ErrorCode::kInvalidArgument,
                 "bad --drone '" + text + "': " + why + " (expected name:airframe:x,y,z[:yaw_deg[:payload[:attached]]])");
  };
  const auto parts = Split(text, ':');
  if (parts.size() < 3 || parts.size() > 6) return bad("wrong number of ':' fields");
  DroneSpec d;
  d.name = parts[0];
  d.airframe = parts[1];
  if (d.name.empty()) return bad("empty name");
  if (d.airframe.empty()) return bad("empty airframe");
  const auto xyz = Split(parts[2], ',');
  if (xyz.size() != 3 || !ToDouble(xyz[0], &d.x_m) || !ToDouble(xyz[1], &d.y_m) || !ToDouble(xyz[2], &d.z_m)) {
    return bad("position must be x,y,z in metres");
  }
  if (parts.size() > 3 && !parts[3].empty() && !ToDouble(parts[3], &d.yaw_deg)) {
    return bad("yaw must be a number of degrees");
  }
  if (parts.size() > 4) d.payload = parts[4];
  if (parts.size() > 5) {
    if (parts[5] != "attached" && parts[5] != "ground") return bad("the last field must be 'attached' or 'ground'");
    d.payload_attached = parts[5] == "attached";
  }
  d.where = "--drone " + d.name;
  return d;
}

Result<std::vector<DroneSpec>> ParseDronesFile(const yaml::Node& root) {
  const yaml::Node* list = &root;
  if (root.is_mapping()) {
    list = root.Find("drones");
    if (list == nullptr) return Error(ErrorCode::kInvalidArgument, "expected a list of drones or a 'drones:' key", root.Where());
  }
  if (!list->is_sequence()) return Error(ErrorCode::kInvalidArgument, "expected a list of drones", list->Where());
  std::vector<DroneSpec> out;
  for (const yaml::Node& item : list->items()) {
    DroneSpec d;
    std::array<double, 3> pose{};
    yaml::MapReader r(item, "drone");
    r.Required("name", &d.name).Required("airframe", &d.airframe).Required("pose", &pose)
        .Optional("yaw_deg", &d.yaw_deg).Optional("payload", &d.payload).Optional("payload_attached", &d.payload_attached);
    if (auto s = r.Finish(); !s) return s.error();
    d.x_m = pose[0];
    d.y_m = pose[1];
    d.z_m = pose[2];
    d.where = item.Where();
    out.push_back(std::move(d));
  }
  return out;
}

Result<std::vector<DroneSpec>> LoadDronesFile(const std::string& path) {
  auto doc = yaml::ParseFile(path);
  if (!doc) return doc.error();
  return ParseDronesFile(*doc);
}

std::string AirframePathFor(const std::string& airframe, const std::string& airframes_dir) {
  const bool is_path = airframe.find('/') != std::string::npos ||
                       (airframe.size() > 5 && airframe.compare(airframe.size() - 5, 5, ".yaml") == 0);
  return is_path ? airframe : airframes_dir + "/" + airframe + ".yaml";
}

}  // namespace swarmbox::physics
