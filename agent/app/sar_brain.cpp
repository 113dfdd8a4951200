#include "sar_brain.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "mission_options.hpp"
#include "swarmbox/brain/args.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/flight/flight_config.hpp"
#include "swarmbox/raft/mission_command.hpp"
#include "swarmbox/raft/mission_state_machine.hpp"

namespace swarmbox::agent {
namespace {

using flight::Vec3;
using swarm::Role;
using swarm::SetpointKind;

// On the ground for the behaviours: the flight stack's init, idle and landed (flight::FlightModeName).
bool OnGround(std::string_view mode) { return mode == "init" || mode == "idle" || mode == "landed"; }

Vec3 V(const brain::Vec3& v) { return Vec3(v.x, v.y, v.z); }
brain::Vec3 B(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

double YawOf(const double q[4]) { return flight::YawOf(flight::Quat(q[0], q[1], q[2], q[3])); }

// args[key] as a number; absent: unchanged. kInvalidArgument naming the key otherwise.
// `text` as a whole finite number, or nullopt.
std::optional<double> FiniteNumber(const std::string& text) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

Status ArgNumber(const brain::Context& ctx, const std::string& key, double* out) {
  const auto it = ctx.args.find(key);
  if (it == ctx.args.end()) return Ok{};
  const std::optional<double> v = FiniteNumber(it->second);
  if (!v) {
    return Error(ErrorCode::kInvalidArgument, "sar brain: arg " + key + " '" + it->second + "': expected a number");
  }
  *out = *v;
  return Ok{};
}

}  // namespace

std::string EncodeMissionMode(Role role, std::string_view mode) {
  return std::string(swarm::RoleName(role)) + "/" + std::string(mode);
}

namespace {

// DecodeMissionMode without a copy of the mode.
bool SplitMissionMode(std::string_view text, Role* role, std::string_view* mode) {
  const std::size_t slash = text.find('/');
  if (slash == std::string_view::npos || slash + 1 >= text.size()) return false;
  const std::string_view r = text.substr(0, slash);
  if (r == "scout") {
    *role = Role::kScout;
  } else if (r == "lifter") {
    *role = Role::kLifter;
  } else {
    return false;
  }
  *mode = text.substr(slash + 1);
  return true;
}

}  // namespace

bool DecodeMissionMode(std::string_view text, Role* role, std::string* mode) {
  std::string_view m;
  if (!SplitMissionMode(text, role, &m)) return false;
  *mode = std::string(m);
  return true;
}

std::string EncodeStatusMessage(std::int64_t t_ns, std::string_view status, double x_m, double y_m) {
  char xy[64];
  std::snprintf(xy, sizeof xy, " %.2f %.2f", x_m, y_m);
  return std::to_string(t_ns) + " " + std::string(status) + xy;
}

bool DecodeStatusMessage(std::string_view payload, std::int64_t* t_ns, std::string* status, double* x_m,
                         double* y_m) {
  // Four fields separated by single spaces; numbers parsed whole (from_chars), nothing after.
  std::array<std::string_view, 4> f;
  std::size_t from = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const std::size_t sp = i + 1 < f.size() ? payload.find(' ', from) : payload.size();
    if (sp == std::string_view::npos || sp == from) return false;
    f[i] = payload.substr(from, sp - from);
    from = sp + 1;
  }
  if (f[3].find(' ') != std::string_view::npos) return false;
  const auto whole = [](std::string_view text, auto* v) {
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), *v);
    return ec == std::errc() && end == text.data() + text.size();
  };
  double x = 0, y = 0;
  std::int64_t t = 0;
  if (!whole(f[0], &t) || !whole(f[2], &x) || !whole(f[3], &y) || !std::isfinite(x) || !std::isfinite(y)) {
    return false;
  }
  Role role;
  std::string_view mode;
  if (!SplitMissionMode(f[1], &role, &mode)) return false;
  *t_ns = t;
  status->assign(f[1]);
  *x_m = x;
  *y_m = y;
  return true;
}

brain::Event ToBrainEvent(const LogEvent& e) {
  brain::Event b;
  for (auto& [key, value] : ParseLogfmt(e.str())) {
    if (key == "t" || key == "node") continue;
    if (key == "event" && b.name.empty()) {
      b.name = std::move(value);
      continue;
    }
    b.fields.emplace_back(std::move(key), std::move(value));
  }
  return b;
}

namespace {

// The lifter's payload from the airframe model: its sling, and where it lies on the ground (the
// model's rule, the one the physics server places it by).
Status ApplyLifterPayload(const airframe::Airframe& af, SarBrainConfig* c) {
  auto payload = af.FindPayload(c->payload);
  if (!payload) {
    std::string known;
    for (const airframe::PayloadSpec& p : af.payloads) known += (known.empty() ? "" : ", ") + p.name;
    return Error(ErrorCode::kInvalidArgument, "--payload '" + c->payload + "': airframe " + af.name + " has " +
                                                  (known.empty() ? std::string("no payloads") : "payloads " + known));
  }
  const airframe::PayloadSpec& p = **payload;
  c->payload_sling_length_m = p.sling_length_m;
  c->payload_hook_m = Vec3(p.hook_m.x, p.hook_m.y, p.hook_m.z);
  const airframe::GroundPlacement ground = airframe::PayloadOnGround(af, p);
  c->payload_offset_m = Eigen::Vector2d(ground.offset_x_m, ground.offset_y_m);
  c->payload_half_height_m = ground.half_height_m;
  return Ok{};
}

}  // namespace

Result<SarBrainConfig> SarBrainConfigFrom(const brain::Context& ctx) {
  auto af = airframe::LoadAirframe(ctx.airframe_path);
  if (!af) return af.error().Context("sar brain: loading the airframe");
  return SarBrainConfigFrom(ctx, *af);
}

namespace {

// A MissionTuning number an arg may set: a field of MissionTuning or of its FusionParams (the
// other pointer null). In the order the args are read (the first bad one is the one reported).
struct TuningArg {
  const char* key;
  double MissionTuning::*field;
  double swarm::FusionParams::*fusion_field;
};

constexpr TuningArg kTuningArgs[] = {
    {"mission_dt_s", &MissionTuning::mission_dt_s, nullptr},
    {"search_margin_m", &MissionTuning::search_margin_m, nullptr},
    {"scout_altitude_m", &MissionTuning::scout_altitude_m, nullptr},
    {"scout_cruise_m_s", &MissionTuning::scout_cruise_m_s, nullptr},
    {"scout_takeoff_step_m", &MissionTuning::scout_takeoff_step_m, nullptr},
    {"takeoff_wave_s", &MissionTuning::takeoff_wave_s, nullptr},
    {"takeoff_grid_m", &MissionTuning::takeoff_grid_m, nullptr},
    {"scout_orbit_radius_m", &MissionTuning::scout_orbit_radius_m, nullptr},
    {"scout_orbit_time_s", &MissionTuning::scout_orbit_time_s, nullptr},
    {"lifter_transit_altitude_m", &MissionTuning::lifter_transit_altitude_m, nullptr},
    {"lifter_loading_time_s", &MissionTuning::lifter_loading_time_s, nullptr},
    {"leader_start_timeout_s", &MissionTuning::leader_start_timeout_s, nullptr},
    {"member_timeout_s", &MissionTuning::member_timeout_s, nullptr},
    {"member_min_wall_s", &MissionTuning::member_min_wall_s, nullptr},
    {"assignment_settle_s", &MissionTuning::assignment_settle_s, nullptr},
    {"sighting_dedupe_m", &MissionTuning::sighting_dedupe_m, nullptr},
    {"status_every_s", &MissionTuning::status_every_s, nullptr},
    {"scout_min_clearance_m", &MissionTuning::scout_min_clearance_m, nullptr},
    {"load_check_climb_m", &MissionTuning::load_check_climb_m, nullptr},
    {"load_check_delay_s", &MissionTuning::load_check_delay_s, nullptr},
    {"load_check_fraction", &MissionTuning::load_check_fraction, nullptr},
    {"fusion_prior", nullptr, &swarm::FusionParams::prior},
    {"fusion_max_view_confidence", nullptr, &swarm::FusionParams::max_view_confidence},
    {"fusion_min_baseline_m", nullptr, &swarm::FusionParams::min_baseline_m},
    {"fusion_min_pass_interval_s", nullptr, &swarm::FusionParams::min_pass_interval_s},
    {"fusion_detector_recall", nullptr, &swarm::FusionParams::detector_recall},
    {"fusion_false_repeat", nullptr, &swarm::FusionParams::false_repeat},
    {"fusion_confirm_belief", nullptr, &swarm::FusionParams::confirm_belief},
    {"fusion_reject_belief", nullptr, &swarm::FusionParams::reject_belief},
    {"fusion_miss_in_view_m", nullptr, &swarm::FusionParams::miss_in_view_m},
    {"fusion_min_miss_height_m", nullptr, &swarm::FusionParams::min_miss_height_m},
    {"fusion_max_miss_height_m", nullptr, &swarm::FusionParams::max_miss_height_m},
    {"fusion_revisit_after_s", nullptr, &swarm::FusionParams::revisit_after_s},
    {"fusion_revisit_timeout_s", nullptr, &swarm::FusionParams::revisit_timeout_s},
    {"fusion_close_look_height_m", nullptr, &swarm::FusionParams::close_look_height_m},
    {"fusion_max_search_log_odds", nullptr, &swarm::FusionParams::max_search_log_odds},
    {"fusion_max_close_view_confidence", nullptr, &swarm::FusionParams::max_close_view_confidence},
    {"fusion_close_recall", nullptr, &swarm::FusionParams::close_recall},
    {"fusion_close_false_repeat", nullptr, &swarm::FusionParams::close_false_repeat},
    {"revisit_look_s", &MissionTuning::revisit_look_s, nullptr},
    {"revisit_look_altitude_m", &MissionTuning::revisit_look_altitude_m, nullptr},
};
// The fusion's counts, read after kTuningArgs as whole numbers.
constexpr const char* kFusionConfirmViewsArg = "fusion_confirm_views";
constexpr const char* kFusionMaxRevisitsArg = "fusion_max_revisits";

// The fields of the config that come straight from the Context, the airframe and the world.
SarBrainConfig BaseConfig(const brain::Context& ctx, const airframe::Airframe& af, const WorldView& world) {
  SarBrainConfig c;
  c.name = ctx.self;
  c.members = ctx.members;
  c.airframe = af.name;
  c.payload = ctx.payload;
  c.base_height_m = af.base_height_m;
  c.vehicle_mass_kg = af.mass_kg;
  c.geofence_size_x_m = world.size_x_m;
  c.geofence_size_y_m = world.size_y_m;
  c.camera = af.camera;
  c.depth_camera = af.stereo.enabled;
  c.period_s = static_cast<double>(ctx.period_ns) * 1e-9;
  return c;
}

// args `start` "x,y,z": the take-off spot; absent: unchanged (the first estimate decides).
Status ApplyStartArg(const brain::Context& ctx, SarBrainConfig* c) {
  const auto it = ctx.args.find("start");
  if (it == ctx.args.end()) return Ok{};
  double x = 0, y = 0, z = 0;
  char tail = 0;
  if (std::sscanf(it->second.c_str(), "%lf,%lf,%lf%c", &x, &y, &z, &tail) != 3) {
    return Error(ErrorCode::kInvalidArgument,
                 "sar brain: arg start '" + it->second + "': expected x,y,z in metres");
  }
  c->has_home = true;
  c->home_m = Vec3(x, y, z);
  return Ok{};
}

// The args kTuningArgs names, then the fusion's two counts, each checked.
Status ApplyTuningArgs(const brain::Context& ctx, MissionTuning* t) {
  for (const TuningArg& arg : kTuningArgs) {
    double* value = arg.field != nullptr ? &(t->*arg.field) : &(t->fusion.*arg.fusion_field);
    SWARMBOX_TRY(ArgNumber(ctx, arg.key, value));
  }
  if (!(t->mission_dt_s > 0))
    return Error(ErrorCode::kInvalidArgument, "sar brain: arg mission_dt_s must be > 0");
  if (!(t->takeoff_wave_s >= 0) || !(t->takeoff_grid_m > 0)) {
    return Error(ErrorCode::kInvalidArgument,
                 "sar brain: args takeoff_wave_s must be >= 0, takeoff_grid_m > 0");
  }
  if (!(t->status_every_s > 0)) {
    return Error(ErrorCode::kInvalidArgument, "sar brain: arg status_every_s must be > 0");
  }
  double fusion_confirm_views = t->fusion.confirm_views;
  double fusion_max_revisits = t->fusion.max_revisits;
  SWARMBOX_TRY(ArgNumber(ctx, kFusionConfirmViewsArg, &fusion_confirm_views));
  SWARMBOX_TRY(ArgNumber(ctx, kFusionMaxRevisitsArg, &fusion_max_revisits));
  t->fusion.confirm_views = static_cast<int>(fusion_confirm_views);
  t->fusion.max_revisits = static_cast<int>(fusion_max_revisits);
  if (const std::string why = swarm::FusionParamsProblem(t->fusion); !why.empty()) {
    return Error(ErrorCode::kInvalidArgument, "sar brain: fusion args: " + why);
  }
  if (!(t->revisit_look_s >= 0))
    return Error(ErrorCode::kInvalidArgument, "sar brain: arg revisit_look_s must be >= 0");
  // A close look must count as one: from the look altitude (+ the revisit's 2 m) the viewer is
  // within fusion_close_look_height_m, and its miss within the fusion's miss heights.
  if (t->revisit_look_altitude_m != 0 &&
      !(t->revisit_look_altitude_m >= t->fusion.min_miss_height_m &&
        t->revisit_look_altitude_m + swarm::kRevisitHeightToleranceM <= t->fusion.close_look_height_m)) {
    return Error(ErrorCode::kInvalidArgument,
                 "sar brain: arg revisit_look_altitude_m must be 0 or at least fusion_min_miss_height_m and "
                 "2 m below fusion_close_look_height_m");
  }
  if (!(t->search_margin_m >= 0))  // < 0 would send the lanes outside the geofence
    return Error(ErrorCode::kInvalidArgument, "sar brain: arg search_margin_m must be >= 0");
  return Ok{};
}

}  // namespace

std::vector<std::string> SarTuningKeys() {
  std::vector<std::string> keys;
  for (const TuningArg& arg : kTuningArgs) keys.emplace_back(arg.key);
  keys.emplace_back(kFusionConfirmViewsArg);
  keys.emplace_back(kFusionMaxRevisitsArg);
  return keys;
}

Result<std::map<std::string, std::string>> ParseMissionTuning(std::string_view json) {
  auto args = brain::ParseBrainArgs(json, "--mission-tuning");
  if (!args) return std::move(args).error();
  const std::vector<std::string> known = SarTuningKeys();
  for (const auto& [key, text] : *args) {
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      std::string list;
      for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
      return Error(ErrorCode::kInvalidArgument,
                   "--mission-tuning: unknown key '" + key + "'; the SAR mission tunes " + list);
    }
    if (!FiniteNumber(text)) {
      return Error(ErrorCode::kInvalidArgument, "--mission-tuning: " + key + " '" + text + "': expected a number");
    }
  }
  return args;
}

Result<SarBrainConfig> SarBrainConfigFrom(const brain::Context& ctx, const airframe::Airframe& af) {
  auto world = LoadWorldView(ctx.world_path);
  if (!world) return world.error();
  if (!af.has_camera) {
    return Error(ErrorCode::kInvalidArgument, "loading the airframe's camera: airframe has no camera mapping",
                 af.source);
  }
  SarBrainConfig c = BaseConfig(ctx, af, *world);
  SWARMBOX_TRY(ApplyStartArg(ctx, &c));
  SWARMBOX_TRY(ApplyTuningArgs(ctx, &c.tuning));
  if (!c.payload.empty()) SWARMBOX_TRY(ApplyLifterPayload(af, &c));
  return c;
}

void NetemWallClock::OnState(const std::string& drone, std::int64_t t_ns, double wall_s) {
  auto [it, fresh] = heard.try_emplace(drone, Heard{t_ns, wall_s});
  if (!fresh && t_ns >= it->second.t_ns) it->second = {t_ns, wall_s};
}

// ---- the replicated mission ----------------------------------------------------------------------

struct SarMissionState::Impl {
  raft::MissionStateMachine machine;
  raft::EventSink sink;  // the machine's lines -> the Context's log
};

namespace {

// Forwards every call to a machine owned elsewhere (the brain's SarMissionState).
class MachineRef final : public raft::StateMachine {
 public:
  explicit MachineRef(raft::StateMachine& target) : target_(target) {}
  void Apply(std::uint64_t index, std::span<const std::uint8_t> data, const raft::EventOut& events) override {
    target_.Apply(index, data, events);
  }
  raft::Bytes Snapshot() const override { return target_.Snapshot(); }
  Status Restore(std::span<const std::uint8_t> snapshot) override { return target_.Restore(snapshot); }
  void OnSnapshotInstalled(std::uint64_t index, const raft::EventOut& events) override {
    target_.OnSnapshotInstalled(index, events);
  }
  void ReplayRestored(std::uint64_t after, std::vector<raft::Committed>* out) const override {
    target_.ReplayRestored(after, out);
  }

 private:
  raft::StateMachine& target_;
};

}  // namespace

SarMissionState::SarMissionState(std::function<void(const brain::Event&)> log) : impl_(std::make_unique<Impl>()) {
  if (log) impl_->sink = [log = std::move(log)](const LogEvent& e) { log(ToBrainEvent(e)); };
}
SarMissionState::~SarMissionState() = default;

void SarMissionState::Apply(std::uint64_t index, std::span<const std::uint8_t> entry) {
  // Undecodable bytes and rejected commands change nothing (MissionStateMachine), the same way
  // on every drone. The line's t and node are the host's to stamp (Context::log).
  impl_->machine.Apply(index, entry, raft::EventOut(0.0, "", impl_->sink));
}

std::vector<std::uint8_t> SarMissionState::Snapshot() const { return impl_->machine.Snapshot(); }

bool SarMissionState::Restore(std::span<const std::uint8_t> snapshot) { return impl_->machine.Restore(snapshot).ok(); }

const raft::MissionState& SarMissionState::mission() const { return impl_->machine.mission(); }

std::unique_ptr<raft::StateMachine> SarMissionState::RaftMachine() { return std::make_unique<MachineRef>(impl_->machine); }

// ---- the brain -----------------------------------------------------------------------------------

Result<std::unique_ptr<SarBrain>> SarBrain::Create(const brain::Context& ctx, const NetemWallClock* wall) {
  auto config = SarBrainConfigFrom(ctx);
  if (!config) return config.error();
  return Create(*config, ctx.log, wall);
}

Result<std::unique_ptr<SarBrain>> SarBrain::Create(const SarBrainConfig& c, std::function<void(const brain::Event&)> log,
                                                   const NetemWallClock* wall) {
  if (c.name.empty()) return Error(ErrorCode::kInvalidArgument, "mission: no drone name");
  if (std::find(c.members.begin(), c.members.end(), c.name) == c.members.end()) {
    return Error(ErrorCode::kInvalidArgument, "mission: --members does not include '" + c.name + "'");
  }
  if (!(c.period_s > 0)) return Error(ErrorCode::kInvalidArgument, "mission: the brain period must be > 0");
  if (!(c.geofence_size_x_m > 2 * c.tuning.search_margin_m) || !(c.geofence_size_y_m > 2 * c.tuning.search_margin_m)) {
    return Error(ErrorCode::kInvalidArgument, "mission: the world's geofence is too small to search");
  }
  auto spec = swarm::BatterySpecFor(c.airframe);
  if (!spec) return spec.error().Context("mission battery model");
  return std::unique_ptr<SarBrain>(new SarBrain(c, swarm::BatteryModel(*spec), std::move(log), wall));
}

namespace {

swarm::FlockingParams FlockParams(const MissionTuning& t) {
  swarm::FlockingParams p;
  p.v_flock_m_s = t.scout_cruise_m_s;
  p.v_max_m_s = t.scout_cruise_m_s;
  return p;
}

}  // namespace

SarBrain::SarBrain(const SarBrainConfig& config, swarm::BatteryModel battery,
                   std::function<void(const brain::Event&)> log, const NetemWallClock* wall)
    : config_(config),
      log_(std::move(log)),
      wall_(wall),
      role_(config.payload.empty() ? Role::kScout : Role::kLifter),
      battery_(std::move(battery)),
      flock_(FlockParams(config.tuning),
             swarm::Geofence::Centered(config.geofence_size_x_m, config.geofence_size_y_m)),
      mode_(EncodeMissionMode(role_, "on_ground")),
      members_(config_.members, config_.name) {
  neighbours_.reserve(config_.members.size());
  // The periodic status messages of the members spread over the period (by place in the member
  // list), not all in the same step.
  const auto at = std::find(config_.members.begin(), config_.members.end(), config_.name);
  const auto n = static_cast<double>(std::max<std::size_t>(1, config_.members.size()));
  status_due_s_ = config_.tuning.status_every_s * static_cast<double>(at - config_.members.begin()) / n;
}

std::unique_ptr<SarMissionState> SarBrain::MakeMissionState() {
  return std::make_unique<SarMissionState>(log_);
}

void SarBrain::OnNeighbours(const Now& now, std::span<const brain::Neighbour> neighbours) {
  neighbours_.clear();
  for (const brain::Neighbour& n : neighbours) {
    if (n.name == config_.name) continue;
    Role role;
    std::string_view mode;
    if (!SplitMissionMode(n.status, &role, &mode)) continue;  // not a SAR agent
    double wall_s = std::numeric_limits<double>::quiet_NaN();
    if (wall_ != nullptr) {
      // netem: when this very state was taken off the radio (the side channel keeps the newest).
      const auto h = wall_->heard.find(n.name);
      if (h != wall_->heard.end() && h->second.t_ns == n.t_ns) wall_s = h->second.wall_s;
    }
    const double sent_s = static_cast<double>(n.t_ns) * 1e-9;
    if (!members_.IsPeer(n.name)) continue;
    // (Ignored by the table when its status message was newer: its state still steers flocking.)
    members_.Update(n.name, sent_s, role, mode, Eigen::Vector2d(n.position_m.x, n.position_m.y), wall_s);
    if (n.position_m.z < home_m_.z() + 1.5) continue;  // on the ground: not in the way
    neighbours_.push_back({V(n.position_m), V(n.velocity_m_s), std::max(0.0, now.t_s - sent_s)});
  }
}

void SarBrain::OnStatus(const Now& now, const brain::Message& m) {
  std::int64_t t_ns = 0;
  double x = 0, y = 0;
  if (!DecodeStatusMessage(
          std::string_view(reinterpret_cast<const char*>(m.payload.data()), m.payload.size()), &t_ns,
          &status_scratch_, &x, &y)) {
    return;
  }
  Role role;
  std::string_view mode;
  (void)SplitMissionMode(status_scratch_, &role, &mode);  // DecodeStatusMessage checked it
  // netem: received between the previous Step and this one (wall_->now_s is this Step's).
  members_.Update(m.from, static_cast<double>(t_ns) * 1e-9, role, mode, Eigen::Vector2d(x, y),
                  wall_ != nullptr ? now.wall_s : std::numeric_limits<double>::quiet_NaN());
}

void SarBrain::SendStatus(const Now& now, brain::Output& out) {
  if (mode_ == sent_status_ && now.t_s < status_due_s_) return;
  sent_status_ = mode_;
  // The periodic ones keep their phase (spread over the members); a change goes out at once.
  while (status_due_s_ <= now.t_s) status_due_s_ += config_.tuning.status_every_s;
  const std::string text = EncodeStatusMessage(static_cast<std::int64_t>(std::llround(now.t_s * 1e9)), mode_,
                                               now.pos_m.x(), now.pos_m.y());
  brain::Message msg;
  // to "" = broadcast: every member keeps its table (a new leader too)
  msg.topic = std::string(kStatusTopic);
  msg.payload.assign(text.begin(), text.end());
  out.messages.push_back(std::move(msg));
}

namespace {

// The geofence (|x| <= size_x / 2, |y| <= size_y / 2) shrunk by `by_m` on every side.
swarm::Rect GeofenceShrunk(const SarBrainConfig& c, double by_m) {
  return {-c.geofence_size_x_m / 2 + by_m, -c.geofence_size_y_m / 2 + by_m, c.geofence_size_x_m / 2 - by_m,
          c.geofence_size_y_m / 2 - by_m};
}

// The scout's behaviour for a mission started at t_s from home_m.
// A scout's revisits and sightings: where it may look from and report, from how low, how long.
void SetRevisits(const SarBrainConfig& c, swarm::ScoutConfig* s) {
  const MissionTuning& t = c.tuning;
  s->revisit_look_s = t.revisit_look_s;
  s->revisit_look_altitude_m = std::min(t.revisit_look_altitude_m, t.scout_altitude_m);
  s->sighting_area = GeofenceShrunk(c, 0.0);
  // The wall repulsion keeps a drone at rest this far from the geofence (12.45 m with the defaults).
  const double standoff_m = swarm::WallStandoffM(FlockParams(t));
  s->revisit_area = GeofenceShrunk(c, standoff_m);
  // The last stretch of a revisit is flown in position mode (scout_behaviour.hpp).
  s->revisit_approach_m = standoff_m + 5.0;
}

swarm::ScoutConfig ScoutConfigFor(const SarBrainConfig& c, const Vec3& home_m, double t_s,
                                  bool lifter_present) {
  const MissionTuning& t = c.tuning;
  swarm::ScoutConfig s;
  s.name = c.name;
  s.home_m = home_m;
  s.base_height_m = c.base_height_m;
  s.search_altitude_m = t.scout_altitude_m;
  // The estimator settles on the ground (as the plan's preflight), then this scout's wave.
  const int wave = swarm::TakeoffWave(home_m.head<2>(), t.takeoff_grid_m);
  s.takeoff_delay_s = t_s + 2.0 + t.takeoff_wave_s * wave;
  s.return_layer = wave;  // home in the wave's altitude layer (swarm::ScoutConfig::return_layer)
  s.hfov_rad = c.camera.hfov_rad;
  s.width_px = c.camera.width_px;
  s.height_px = c.camera.height_px;
  s.cruise_speed_m_s = t.scout_cruise_m_s;
  s.orbit_radius_m = t.scout_orbit_radius_m;
  s.lifter_present = lifter_present;
  s.dedupe_radius_m = t.sighting_dedupe_m;
  s.report_baseline_m = t.fusion.min_baseline_m;  // one view per counted baseline, no more
  SetRevisits(c, &s);
  s.min_clearance_m = c.depth_camera ? t.scout_min_clearance_m : 0.0;  // no depth camera: nothing seen
  s.keep_searching_during_rescue = true;  // the lifter does the rescue; scouts finish the search
  s.return_when_swept = true;             // nothing left to see: land, do not loiter
  s.approach_height_m = 5.0;              // descend at vel_max_down, land the last 5 m
  // Flock (with its repulsion) until 3 m from home, less than the 4 m take-off grid, so the
  // straight position-mode leg stays in the drone's own cell: from 10 m out it crossed the
  // columns of neighbours descending over their homes (kinematic rig, 25 scouts: 0.81 m; with
  // 3 m the closest approach is the flock's, 4.05 m).
  s.home_approach_m = 3.0;
  s.orbit_time_s = t.scout_orbit_time_s;
  // After a restart, sighting sequence numbers continue above any used before (sim ms).
  s.first_sighting_seq = static_cast<std::uint64_t>(t_s * 1000.0) + 1;
  return s;
}

// The lifter's sequence from home_m, with the payload of the config.
swarm::LifterConfig LifterConfigFor(const SarBrainConfig& c, const Vec3& home_m) {
  swarm::LifterConfig l;
  l.name = c.name;
  l.home_m = home_m;
  l.base_height_m = c.base_height_m;
  l.transit_altitude_m = c.tuning.lifter_transit_altitude_m;
  l.hook_below_body_m = -c.payload_hook_m.z();
  l.sling_length_m = c.payload_sling_length_m;
  l.payload_half_height_m = c.payload_half_height_m;
  l.loading_time_s = c.tuning.lifter_loading_time_s;
  l.stretcher_start_offset_m = c.payload_offset_m;
  l.standby_after_delivery = true;
  // With a depth camera, survey the drop point (from survey_height_m, 8 m: the OAK-D Pro's 72 x 45
  // deg sees 11.6 x 7.3 m of ground there; depth::DropSpotConfig has why not higher).
  l.survey_drop_point = c.depth_camera;
  l.release_sink_m = -0.3;  // let go 0.3 m above the ground: no drag on a grounded stretcher
  // Hooking needs the hook within 4 +- 0.5 m of the stretcher's centre: 1 m sideways at 4 m
  // below changes that distance by 0.12 m, so the horizontal tolerance can be 1 m.
  l.position_tolerance_m = 1.0;
  l.settle_speed_m_s = 0.5;
  return l;
}

// The leader's planner (every drone holds one: a new leader knows the sectors): the geofence
// shrunk by the search margin.
swarm::LeaderConfig LeaderConfigFor(const SarBrainConfig& c) {
  const MissionTuning& t = c.tuning;
  swarm::LeaderConfig lc;
  lc.name = c.name;
  lc.search_area = GeofenceShrunk(c, t.search_margin_m);
  lc.retry_s = 2.0;
  lc.start_timeout_s = t.leader_start_timeout_s;
  lc.member_timeout_s = t.member_timeout_s;
  lc.member_min_wall_s = t.member_min_wall_s;
  lc.assignment_settle_s = t.assignment_settle_s;
  lc.fusion = t.fusion;
  return lc;
}

}  // namespace

void SarBrain::Start(const Now& now, brain::Output& out) {
  if (now.flight_mode == "init" || now.flight_mode.empty()) return;  // the estimator is not ready
  // Wait (up to 10 s) until every member was heard, so roles are known (lifter present or not).
  const bool lifter_present = role_ == Role::kLifter || members_.lifter_heard();
  std::size_t heard = members_.heard();
  if (members_.Find(config_.name) != nullptr) --heard;  // this drone (UpdateSelf) is not a peer
  if (heard + 1 < config_.members.size() && now.t_s < 10.0) return;
  home_m_ = config_.has_home ? config_.home_m : Vec3(now.pos_m - Vec3(0, 0, config_.base_height_m));
  if (role_ == Role::kScout) {
    scout_.emplace(ScoutConfigFor(config_, home_m_, now.t_s, lifter_present));
  } else {
    lifter_.emplace(LifterConfigFor(config_, home_m_));
  }
  leader_.emplace(LeaderConfigFor(config_));
  out.events.push_back(ToBrainEvent(LogEvent(now.t_s, config_.name, "mission_start")
                                        .Add("role", swarm::RoleName(role_))
                                        .Add("home_x", home_m_.x(), 2)
                                        .Add("home_y", home_m_.y(), 2)
                                        .Add("lifter_present", lifter_present)));
}

namespace {

const SarMissionState& MissionStateOf(const brain::Input& in) {
  const auto* state = dynamic_cast<const SarMissionState*>(in.state);
  if (state == nullptr) {
    std::fprintf(stderr, "SarBrain::Step: Input::state is not the brain's SarMissionState (a wiring bug)\n");
    std::abort();
  }
  return *state;
}

}  // namespace

SarBrain::Now SarBrain::ReadNow(const brain::Input& in) const {
  Now now;
  now.t_s = static_cast<double>(in.t_ns) * 1e-9;
  if (wall_ != nullptr) now.wall_s = wall_->now_s;
  now.flight_mode = in.self.flight_mode;
  now.on_ground = OnGround(in.self.flight_mode);
  now.pos_m = V(in.self.position_m);
  now.vel_m_s = V(in.self.velocity_m_s);
  now.yaw_rad = YawOf(in.self.attitude_wxyz);
  now.mission = &MissionStateOf(in).mission();
  now.is_leader = in.is_leader;
  for (const brain::FlightEvent& e : in.flight_events) now.hover_event = now.hover_event || e.name == "hover";
  now.mass_estimate_kg = in.self.mass_estimate_kg;
  return now;
}

void SarBrain::OnDetections(const Now& now, std::span<const brain::Detection> detections) {
  for (const brain::Detection& d : detections) {
    swarm::GroundDetection g;
    g.capture_time_s = static_cast<double>(d.t_ns) * 1e-9;
    g.position_m = V(d.position_m);
    g.sigma_m = d.sigma_m;
    g.confidence = d.confidence;
    // The viewpoint: this drone's estimate now, when the detection became visible (capture +
    // the inference latency, 40 ms: <= 0.3 m of flight at 7 m/s, against a 10 m baseline).
    g.viewer_m = now.pos_m;
    visible_.push_back(g);
  }
}

void SarBrain::LogCompleteOnce(const Now& now, brain::Output& out) {
  const raft::MissionState& mission = *now.mission;
  if (mission.phase() != raft::MissionPhase::kComplete || complete_logged_) return;
  complete_logged_ = true;
  std::int64_t rescued = 0;
  for (const raft::Victim& v : mission.victims()) rescued += v.status == raft::VictimStatus::kRescued ? 1 : 0;
  out.events.push_back(ToBrainEvent(LogEvent(now.t_s, config_.name, "mission_complete")
                                        .Add("victims", static_cast<std::int64_t>(mission.victims().size()))
                                        .Add("rescued", rescued)));
}

void SarBrain::Step(const brain::Input& in, brain::Output& out) {
  const Now now = ReadNow(in);
  for (const brain::Message& m : in.messages) {
    if (m.topic == kStatusTopic && m.from != config_.name) OnStatus(now, m);
  }
  // The neighbours once per mission tick (every Step until the mission starts): the host keeps
  // the latest state of each, so nothing is missed, and the work per Step stays bounded.
  const bool started = scout_ || lifter_;
  const bool tick = now.t_s >= next_tick_s_;
  if (!started || tick) OnNeighbours(now, in.neighbours);
  if (role_ == Role::kScout) OnDetections(now, in.detections);

  battery_.Step(config_.period_s, now.vel_m_s, payload_mass_kg(), !now.on_ground);
  if (!started) Start(now, out);
  if (scout_ || lifter_) {
    if (tick || !started) {
      next_tick_s_ = now.t_s + config_.tuning.mission_dt_s;
      if (role_ == Role::kLifter) CheckLoad(now, out);
      RunBehaviour(now, out);
    }
    LogCompleteOnce(now, out);
  }
  SendStatus(now, out);
  out.status = mode_;
}

swarm::MissionInput SarBrain::BehaviourInput(const Now& now) const {
  swarm::MissionInput mi;
  mi.t_s = now.t_s;
  mi.mission = now.mission;
  mi.position_m = now.pos_m;
  mi.velocity_m_s = now.vel_m_s;
  mi.yaw_rad = now.yaw_rad;
  mi.battery_fraction = battery_.fraction();
  const double to_home = (now.pos_m.head<2>() - home_m_.head<2>()).norm();
  mi.battery_low = battery_.IsLow(to_home, std::max(0.0, now.pos_m.z() - home_m_.z()), payload_mass_kg());
  mi.payload_attached = payload_attached_;
  mi.detections = visible_;
  return mi;
}

void SarBrain::RunBehaviour(const Now& now, brain::Output& out) {
  swarm::MissionInput mi = BehaviourInput(now);
  if (scout_) {
    mi.obstacle_top_z_m = std::exchange(obstacle_top_z_m_, std::nullopt);
    scout_->Step(mi, &behaviour_out_);
  } else {
    mi.drop_spot = std::exchange(drop_spot_answer_, std::nullopt);
    lifter_->Step(mi, &behaviour_out_);
    TrackDropSpotQuery(now);
  }
  visible_.clear();
  mode_ = EncodeMissionMode(role_, behaviour_out_.mode);
  for (const raft::MissionCommand& c : behaviour_out_.proposals) out.proposals.push_back(raft::EncodeCommand(c));
  for (const LogEvent& e : behaviour_out_.events) out.events.push_back(ToBrainEvent(e));
  if (behaviour_out_.payload.action != swarm::PayloadAction::kNone) Apply(behaviour_out_.payload, out);
  Drive(now, behaviour_out_.setpoint, out);

  leader_->Track(now.t_s, *now.mission, now.wall_s);  // every drone: a new leader knows when sectors changed
  members_.UpdateSelf(now.t_s, role_, behaviour_out_.mode, now.pos_m.head<2>());
  if (now.is_leader) RunLeader(now, out);
}

void SarBrain::TrackDropSpotQuery(const Now& now) {
  if (!behaviour_out_.want_drop_spot) {
    drop_spot_query_.reset();
    return;
  }
  if (!drop_spot_query_) drop_spot_query_ = DropSpotQuery{.since_t_s = now.t_s};
  drop_spot_query_->default_xy_m = behaviour_out_.drop_spot_default_xy_m;
  drop_spot_query_->yaw_rad = behaviour_out_.drop_spot_yaw_rad;
  drop_spot_query_->ground_z_m = home_m_.z();
  drop_spot_query_->victim_xy_m = behaviour_out_.drop_spot_victim_xy_m;
}

void SarBrain::RunLeader(const Now& now, brain::Output& out) {
  const std::span<const swarm::RosterEntry> roster = members_.Roster(now.t_s, now.wall_s);
  // How the swarm flocks, for the logs and the trial's plots (agent/swarm flock_metrics.hpp).
  if (auto line = flock_log_.Sample(now.t_s, config_.name, roster)) out.events.push_back(ToBrainEvent(*line));
  const bool everyone = roster.size() == config_.members.size();
  if (!(everyone || now.mission->phase() != raft::MissionPhase::kIdle ||
        now.t_s >= config_.tuning.leader_start_timeout_s)) {
    return;  // the search starts once everyone is heard, or at the start timeout
  }
  swarm::MissionOutput lead;
  leader_->Step(now.t_s, *now.mission, roster, &lead, now.wall_s);
  for (const raft::MissionCommand& c : lead.proposals) out.proposals.push_back(raft::EncodeCommand(c));
  for (const LogEvent& e : lead.events) {
    // Every drone logs mission_complete itself when it applies COMPLETE (Step()).
    if (e.str().find(" event=mission_complete") == std::string::npos) out.events.push_back(ToBrainEvent(e));
  }
}

void SarBrain::Apply(const swarm::PayloadRequest& p, brain::Output& out) {
  // The command drives the simulated hook (a world command of the agent): the brain takes the
  // hook's state to be the last command it sent (a refused command shows as
  // event=world_command_rejected in the physics log; the lifter only asks once settled within
  // the hook's reach, and the load check below catches an empty hook).
  if (p.action == swarm::PayloadAction::kAttach) {
    out.commands.push_back(brain::Command::PayloadAttach(p.mass_kg));
    payload_attached_ = true;
    payload_mass_kg_ = p.mass_kg;
    attach_t_s_ = next_tick_s_ - config_.tuning.mission_dt_s;
  } else if (p.action == swarm::PayloadAction::kRelease) {
    out.commands.push_back(brain::Command::PayloadRelease());
    payload_attached_ = false;
    attach_t_s_ = -1.0;
  }
}

void SarBrain::CheckLoad(const Now& now, brain::Output& out) {
  if (attach_t_s_ < 0 || !payload_attached_) return;
  const MissionTuning& t = config_.tuning;
  const double hook_height = -config_.payload_hook_m.z() + config_.payload_sling_length_m + config_.payload_half_height_m;
  const double height = now.pos_m.z() - home_m_.z();
  if (now.t_s - attach_t_s_ < t.load_check_delay_s || height < hook_height + t.load_check_climb_m) return;
  const double load = now.mass_estimate_kg - config_.vehicle_mass_kg;
  const bool ok = load >= t.load_check_fraction * payload_mass_kg_;
  out.events.push_back(ToBrainEvent(LogEvent(now.t_s, config_.name, ok ? "payload_confirmed" : "payload_missing")
                                        .Add("expected_kg", payload_mass_kg_, 1)
                                        .Add("estimated_kg", load, 1)));
  attach_t_s_ = -1.0;
  if (!ok) payload_attached_ = false;  // the world refused the hook: the lifter goes back for it
}

void SarBrain::DriveTakeoff(const Now& now, const swarm::SetpointRequest& sp, bool changed,
                            brain::Output& out) {
  // A short flight-stack take-off, then the climb in position mode (faster: vel_max_up).
  const double height = sp.target_m.z() - now.pos_m.z();
  if (now.on_ground) {
    if (changed || now.flight_mode != "takeoff") {
      out.commands.push_back(
          brain::Command::Takeoff(std::clamp(height, 0.5, config_.tuning.scout_takeoff_step_m)));
      climb_sent_ = false;
    }
  } else if (!climb_sent_ && (now.hover_event || now.flight_mode == "hold")) {
    out.setpoint.assign(1, brain::Setpoint::Position(B(sp.target_m)));
    climb_sent_ = true;
  }
}

void SarBrain::DriveFlock(const Now& now, const swarm::SetpointRequest& sp, bool changed,
                          brain::Output& out) {
  if (changed) flock_.Reset(now.vel_m_s);
  swarm::FlockingInput fi;
  fi.position_m = now.pos_m;
  fi.velocity_m_s = now.vel_m_s;
  fi.goal_m = sp.target_m;
  fi.neighbours = neighbours_;
  const swarm::FlockingOutput f = flock_.Step(fi, config_.tuning.mission_dt_s);
  out.setpoint.assign(1, brain::Setpoint::Velocity(B(f.velocity_m_s), sp.yaw_rad));
  flocking_out_ = f;
}

void SarBrain::Drive(const Now& now, const swarm::SetpointRequest& sp, brain::Output& out) {
  const bool changed = sp.kind != sent_kind_;
  switch (sp.kind) {
    case SetpointKind::kIdle:
      break;
    case SetpointKind::kTakeoff:
      DriveTakeoff(now, sp, changed, out);
      break;
    case SetpointKind::kPosition:
      if (now.on_ground) break;
      if (changed || (sp.target_m - sent_target_m_).norm() > 0.05) {
        out.setpoint.assign(1, brain::Setpoint::Position(B(sp.target_m), sp.yaw_rad));
        sent_target_m_ = sp.target_m;
      }
      break;
    case SetpointKind::kFlock:
      if (!now.on_ground) DriveFlock(now, sp, changed, out);
      break;
    case SetpointKind::kLand:
      if (!now.on_ground && (changed || now.flight_mode != "land")) out.commands.push_back(brain::Command::Land());
      break;
  }
  if (sp.kind != SetpointKind::kPosition) sent_target_m_ = Vec3::Constant(1e9);
  sent_kind_ = sp.kind;
  flocking_ = sp.kind == SetpointKind::kFlock;
}

}  // namespace swarmbox::agent
