#include "mission_options.hpp"

#include <filesystem>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::agent {

std::string_view MissionKindName(MissionKind kind) { return kind == MissionKind::kSar ? "sar" : "plan"; }

Result<MissionKind> ParseMissionKind(std::string_view text) {
  if (text == "plan") return MissionKind::kPlan;
  if (text == "sar") return MissionKind::kSar;
  return Error(ErrorCode::kInvalidArgument, "--mission '" + std::string(text) + "': expected plan or sar");
}

Status ValidateMissionOptions(const MissionOptions& o, bool has_members, bool plan_given) {
  if (o.inference_latency_ms < 0 || o.inference_latency_ms > kMaxInferenceLatencyMs) {
    return Error(ErrorCode::kInvalidArgument, "--inference-latency-ms " + std::to_string(o.inference_latency_ms) +
                                                  ": expected 0.." + std::to_string(kMaxInferenceLatencyMs));
  }
  if (o.kind == MissionKind::kPlan) {
    if (!o.world_path.empty()) return Error(ErrorCode::kInvalidArgument, "--world is for --mission sar (the plan flies without a world)");
    if (!o.payload.empty()) return Error(ErrorCode::kInvalidArgument, "--payload is for --mission sar (the lifter's rescue)");
    if (!o.tuning_json.empty()) return Error(ErrorCode::kInvalidArgument, "--mission-tuning is for --mission sar");
    return Ok{};
  }
  if (!has_members) {
    return Error(ErrorCode::kInvalidArgument,
                 "--mission sar needs --members (the swarm agrees on the mission through Raft)");
  }
  if (o.world_path.empty()) return Error(ErrorCode::kInvalidArgument, "--mission sar needs --world (the search area)");
  if (plan_given) return Error(ErrorCode::kInvalidArgument, "--plan is for --mission plan (sar flies the mission)");
  return Ok{};
}

namespace {

Status ReadNumber(const yaml::Node& map, std::string_view key, double* out, bool positive) {
  const yaml::Node* n = map.Find(key);
  if (n == nullptr) return Ok{};
  auto v = n->AsDouble();
  if (!v) return v.error();
  if (positive && !(*v > 0)) return Error(ErrorCode::kInvalidArgument, std::string(key) + " must be > 0", n->Where());
  *out = *v;
  return Ok{};
}

}  // namespace

Result<WorldView> LoadWorldView(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return Error(ErrorCode::kNotFound, "--world '" + path + "': no such file");
  }
  auto doc = yaml::ParseFile(path);
  if (!doc) return doc.error().Context("--world");
  if (!doc->is_mapping()) return Error(ErrorCode::kInvalidArgument, "--world: expected a mapping", doc->Where());
  WorldView w;
  if (const yaml::Node* n = doc->Find("name")) {
    auto s = n->AsString();
    if (!s) return s.error().Context("--world");
    w.name = *s;
  }
  if (const yaml::Node* g = doc->Find("geofence")) {
    if (!g->is_mapping()) return Error(ErrorCode::kInvalidArgument, "--world: geofence: expected a mapping", g->Where());
    SWARMBOX_TRY(ReadNumber(*g, "size_x_m", &w.size_x_m, true));
    SWARMBOX_TRY(ReadNumber(*g, "size_y_m", &w.size_y_m, true));
  }
  if (const yaml::Node* h = doc->Find("home")) {
    if (!h->is_mapping()) return Error(ErrorCode::kInvalidArgument, "--world: home: expected a mapping", h->Where());
    w.has_home = true;
    SWARMBOX_TRY(ReadNumber(*h, "lat_deg", &w.home_lat_deg, false));
    SWARMBOX_TRY(ReadNumber(*h, "lon_deg", &w.home_lon_deg, false));
    SWARMBOX_TRY(ReadNumber(*h, "alt_m", &w.home_alt_m, false));
  }
  return w;
}

int ElectionTimeoutMsFor(const MissionOptions& options, int configured_ms) {
  const bool lifter = options.kind == MissionKind::kSar && !options.payload.empty();
  return lifter ? 2 * configured_ms : configured_ms;
}

}  // namespace swarmbox::agent
