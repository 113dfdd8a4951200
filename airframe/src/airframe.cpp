#include "swarmbox/airframe/airframe.hpp"

#include <cmath>
#include <numbers>

#include <algorithm>

#include "swarmbox/airframe/yaml_read.hpp"

namespace swarmbox::airframe {
namespace {

using detail::Checked;
using detail::InvalidAt;
using detail::Nested;
using yaml::MapReader;
using yaml::Node;

constexpr double kRtkMaxBaselineKm = 100.0;  // RTK needs a base station within tens of km

// ---- one reader per top-level section (kSections) ----------------------------------------------

void ReadCollision(MapReader& parent, Airframe* af) {
  Nested(parent, "collision", "collision", true, [af](MapReader& c, const Node&) {
    c.Required("box_m", &af->collision_box_m).Optional("offset_m", &af->collision_offset_m);
  });
}

void ReadImpact(MapReader& parent, Airframe* af) {
  Nested(parent, "impact", "impact", false, [af](MapReader& c, const Node& n) {
    Checked(c, n)
        .Positive("hard_landing_speed_m_s", &af->hard_landing_speed_m_s, false)
        .Positive("crash_speed_m_s", &af->crash_speed_m_s, false);
  });
}

void ReadMotorFields(MapReader& r, const Node& n, MotorSpec* m) {
  Checked(r, n)
      .Positive("motor_constant", &m->motor_constant)
      .NonNegative("moment_constant", &m->moment_constant, true)
      .Positive("time_constant_up_s", &m->time_constant_up_s)
      .Positive("time_constant_down_s", &m->time_constant_down_s)
      .Positive("max_rot_velocity_rad_s", &m->max_rot_velocity_rad_s)
      .NonNegative("rotor_drag_coefficient", &m->rotor_drag_coefficient)
      .NonNegative("rolling_moment_coefficient", &m->rolling_moment_coefficient);
}

void ReadMotor(MapReader& parent, Airframe* af) {
  Nested(parent, "motor", "motor", true, [af](MapReader& m, const Node& n) { ReadMotorFields(m, n, &af->motor); });
}

void ReadRotors(MapReader& parent, Airframe* af) {
  const Node* list = parent.Child("rotors", /*required=*/true);
  if (list == nullptr) return;
  if (!list->is_sequence() || list->items().empty()) {
    parent.Fail(Error(ErrorCode::kInvalidArgument, "'rotors' must be a non-empty list", list->Where()));
    return;
  }
  if (list->items().size() > 8) {
    parent.Fail(Error(ErrorCode::kInvalidArgument, "at most 8 rotors are supported", list->Where()));
    return;
  }
  for (const Node& item : list->items()) {
    MapReader r(item, "rotor");
    RotorSpec rotor;
    std::string direction;
    r.Required("position_m", &rotor.position_m).Required("direction", &direction);
    if (r.ok() && direction != "ccw" && direction != "cw") {
      r.Fail(Error(ErrorCode::kInvalidArgument,
                   "rotor direction must be 'ccw' or 'cw' (got '" + direction + "')",
                   item.Find("direction")->Where()));
    }
    rotor.ccw = direction == "ccw";
    if (auto s = r.Finish(); !s) {
      parent.Fail(s.error());
      return;
    }
    af->rotors.push_back(rotor);
  }
}

void ReadImu(MapReader& s, const Node& m, ImuSpec* imu) {
  Checked(s, m)
      .Positive("rate_hz", &imu->rate_hz, false)
      .NonNegative("accel_noise_std_m_s2", &imu->accel_noise_std_m_s2)
      .NonNegative("accel_bias_std_m_s2", &imu->accel_bias_std_m_s2)
      .NonNegative("accel_bias_walk_std_m_s2", &imu->accel_bias_walk_std_m_s2)
      .NonNegative("gyro_noise_std_rad_s", &imu->gyro_noise_std_rad_s)
      .NonNegative("gyro_bias_std_rad_s", &imu->gyro_bias_std_rad_s)
      .NonNegative("gyro_bias_walk_std_rad_s", &imu->gyro_bias_walk_std_rad_s);
}

// fix: standalone: the accuracy figures are the file's; no RTK baseline.
void ReadStandaloneGps(MapReader& s, const Node& m, GpsSpec* gps) {
  Checked(s, m)
      .NonNegative("horizontal_std_m", &gps->horizontal_std_m)
      .NonNegative("vertical_std_m", &gps->vertical_std_m);
  if (s.ok() && m.Find("rtk_baseline_km") != nullptr) {
    s.Fail(InvalidAt(m, "rtk_baseline_km", "gps rtk_baseline_km needs fix: rtk"));
  }
}

// fix: rtk: the accuracy is the receiver's datasheet figure for the baseline, not a free number.
void ReadRtkGps(MapReader& s, const Node& m, GpsSpec* gps) {
  for (const char* key : {"horizontal_std_m", "vertical_std_m"}) {
    if (s.ok() && m.Find(key) != nullptr) {
      s.Fail(InvalidAt(m, key,
                       std::string("gps ") + key + " is set by the RTK receiver model with fix: rtk "
                           "(0.01 m + 1 ppm of rtk_baseline_km); leave it out"));
    }
  }
  double baseline_km = gps->rtk_baseline_km;
  Checked(s, m).NonNegative("rtk_baseline_km", &baseline_km);
  if (s.ok() && baseline_km > kRtkMaxBaselineKm) {
    s.Fail(InvalidAt(m, "rtk_baseline_km",
                     "gps rtk_baseline_km must be at most 100 (RTK needs a base within tens of km)"));
  }
  if (s.ok() && gps->rate_hz > kRtkMaxRateHz) {
    s.Fail(InvalidAt(m, "rate_hz",
                     "gps rate_hz must be at most 20 with fix: rtk (the ZED-F9P's RTK navigation rate)"));
  }
  SetRtkFix(gps, baseline_km);
}

void ReadGps(MapReader& s, const Node& m, GpsSpec* gps) {
  std::string fix = "standalone";
  s.Optional("fix", &fix);
  if (s.ok() && fix != "standalone" && fix != "rtk") {
    s.Fail(InvalidAt(m, "fix", "gps fix must be 'standalone' or 'rtk' (got '" + fix + "')"));
    return;
  }
  Checked(s, m).Positive("rate_hz", &gps->rate_hz, false).NonNegative("velocity_std_m_s", &gps->velocity_std_m_s);
  if (fix == "standalone") {
    ReadStandaloneGps(s, m, gps);
  } else {
    ReadRtkGps(s, m, gps);
  }
}

void ReadSensors(MapReader& parent, Airframe* af) {
  Nested(parent, "sensors", "sensors", false, [af](MapReader& r, const Node&) {
    Nested(r, "imu", "imu", false, [af](MapReader& s, const Node& m) { ReadImu(s, m, &af->imu); });
    Nested(r, "baro", "baro", false, [af](MapReader& s, const Node& m) {
      Checked(s, m).Positive("rate_hz", &af->baro.rate_hz, false).NonNegative("noise_std_pa", &af->baro.noise_std_pa);
    });
    Nested(r, "mag", "mag", false, [af](MapReader& s, const Node& m) {
      Checked(s, m)
          .Positive("rate_hz", &af->mag.rate_hz, false)
          .NonNegative("noise_std_gauss", &af->mag.noise_std_gauss);
    });
    Nested(r, "gps", "gps", false, [af](MapReader& s, const Node& m) { ReadGps(s, m, &af->gps); });
  });
}

void ReadCamera(MapReader& parent, Airframe* af) {
  Nested(parent, "camera", "camera", false, [af](MapReader& r, const Node& n) {
    af->has_camera = true;
    CameraSpec& c = af->camera;
    r.Optional("width_px", &c.width_px).Optional("height_px", &c.height_px).Optional("offset_m", &c.offset_m);
    Checked(r, n)
        .Positive("hfov_rad", &c.hfov_rad, false)
        .Positive("rate_hz", &c.rate_hz, false)
        .NonNegative("trigger_distance_m", &c.trigger_distance_m)
        .NonNegative("trigger_interval_max_s", &c.trigger_interval_max_s)
        .NonNegative("noise_std", &c.noise_std)
        .NonNegative("exposure_ms", &c.exposure_ms)
        .NonNegative("vignetting", &c.vignetting);
    if (r.ok() && c.vignetting >= 1) {
      r.Fail(Error(ErrorCode::kInvalidArgument, "camera vignetting must be below 1", n.Find("vignetting")->Where()));
    }
    if (r.ok() && (c.width_px < 16 || c.height_px < 16 || c.width_px > 4096 || c.height_px > 4096)) {
      r.Fail(Error(ErrorCode::kInvalidArgument, "camera size must be within 16..4096 pixels", n.Where()));
    }
    if (r.ok() && c.hfov_rad >= std::numbers::pi * 0.9) {
      r.Fail(Error(ErrorCode::kInvalidArgument, "camera hfov_rad must be below 0.9 pi", n.Find("hfov_rad")->Where()));
    }
  });
}

// `thermal:` (thermal_spec.cpp): absent or null leaves af->thermal disabled.
void ReadThermal(MapReader& parent, Airframe* af) {
  const Node* n = parent.Child("thermal", false);
  if (n == nullptr) return;
  auto spec = ParseThermalSpec(n);
  if (!spec) {
    parent.Fail(spec.error());
    return;
  }
  // A thermal frame is taken with each camera frame (physics SimServer): the core must keep up.
  if (spec->enabled && af->camera.rate_hz > spec->rate_hz) {
    parent.Fail(InvalidAt(
        *n, "rate_hz",
        "thermal: rate_hz must be at least camera.rate_hz (a frame is taken with each camera frame)"));
    return;
  }
  af->thermal = *spec;
}

// `stereo:` (stereo_spec.cpp): absent or null leaves af->stereo disabled.
void ReadStereo(MapReader& parent, Airframe* af) {
  const Node* n = parent.Child("stereo", false);
  if (n == nullptr) return;
  auto spec = ParseStereoSpec(n);
  if (!spec) {
    parent.Fail(spec.error());
    return;
  }
  af->stereo = *spec;
}

void ReadPayloads(MapReader& parent, Airframe* af) {
  const Node* list = parent.Child("payloads", false);
  if (list == nullptr || list->is_null()) return;
  if (!list->is_sequence()) {
    parent.Fail(Error(ErrorCode::kInvalidArgument, "'payloads' must be a list", list->Where()));
    return;
  }
  for (const Node& item : list->items()) {
    MapReader r(item, "payload");
    PayloadSpec p;
    r.Required("name", &p.name).Required("size_m", &p.size_m).Required("hook_m", &p.hook_m);
    Checked(r, item)
        .Positive("mass_kg", &p.mass_kg)
        .Positive("sling_length_m", &p.sling_length_m)
        .Positive("attach_tolerance_m", &p.attach_tolerance_m, false);
    if (r.ok() && (p.size_m.x <= 0 || p.size_m.y <= 0 || p.size_m.z <= 0)) {
      r.Fail(Error(ErrorCode::kInvalidArgument, "payload size_m must be positive", item.Find("size_m")->Where()));
    }
    if (auto s = r.Finish(); !s) {
      parent.Fail(s.error());
      return;
    }
    af->payloads.push_back(p);
  }
}

void ReadControl(MapReader& parent, Airframe* af) {
  if (const Node* control = parent.Child("control", false)) af->control = *control;  // the flight stack's
}

// The top-level sections, read in this order after the scalar keys; the first error wins. A new
// section: its reader here (a field of Airframe filled by a parse function in its own file).
using SectionReader = void (*)(MapReader& parent, Airframe* af);
constexpr SectionReader kSections[] = {
    ReadCollision, ReadImpact, ReadMotor,   ReadRotors,   ReadSensors,
    ReadCamera,    ReadStereo, ReadThermal, ReadPayloads, ReadControl,
};

// Checks across keys, once every section is read.
Status CheckConsistency(const Node& root, const Airframe& af) {
  auto fail = [&](const char* key, const std::string& msg) { return InvalidAt(root, key, "airframe: " + msg); };
  const Vec3& I = af.inertia_kg_m2;
  if (I.x <= 0 || I.y <= 0 || I.z <= 0) return fail("inertia_kg_m2", "inertia must be positive");
  if (I.x + I.y < I.z || I.y + I.z < I.x || I.x + I.z < I.y) {
    return fail("inertia_kg_m2", "principal moments violate the triangle inequality");
  }
  const Vec3& b = af.collision_box_m;
  if (b.x <= 0 || b.y <= 0 || b.z <= 0) return fail("collision", "collision box_m must be positive");
  if (af.body_drag_coefficient.x < 0 || af.body_drag_coefficient.y < 0 || af.body_drag_coefficient.z < 0) {
    return fail("body_drag_coefficient", "body drag coefficients must be >= 0");
  }
  if (af.crash_speed_m_s < af.hard_landing_speed_m_s) {
    return fail("impact", "crash_speed_m_s must be >= hard_landing_speed_m_s");
  }
  return Ok{};
}

}  // namespace

double Airframe::HoverRotorSpeed(double extra_mass_kg, double gravity_m_s2) const {
  const double n = static_cast<double>(rotors.size());
  return std::sqrt((mass_kg + extra_mass_kg) * gravity_m_s2 / (n * motor.motor_constant));
}

Result<const PayloadSpec*> Airframe::FindPayload(std::string_view payload_name) const {
  auto it = std::find_if(payloads.begin(), payloads.end(), [&](const PayloadSpec& p) { return p.name == payload_name; });
  if (it == payloads.end()) {
    return Error(ErrorCode::kInvalidArgument, "airframe " + name + " has no payload '" + std::string(payload_name) + "'");
  }
  return &*it;
}

GroundPlacement PayloadOnGround(const Airframe& af, const PayloadSpec& payload) {
  GroundPlacement g;
  g.offset_y_m = -(af.collision_box_m.y / 2 + payload.size_m.y / 2 + kGroundPayloadGapM);
  g.half_height_m = payload.size_m.z / 2;
  return g;
}

Result<Airframe> ParseAirframe(const yaml::Node& root, std::string source) {
  Airframe af;
  af.source = std::move(source);
  MapReader r(root, "airframe");
  r.Required("name", &af.name).Required("inertia_kg_m2", &af.inertia_kg_m2);
  Checked(r, root).Positive("mass_kg", &af.mass_kg).NonNegative("base_height_m", &af.base_height_m, true);
  r.Optional("body_drag_coefficient", &af.body_drag_coefficient);
  for (SectionReader read : kSections) {
    if (r.ok()) read(r, &af);
  }
  if (auto s = r.Finish(); !s) return s.error().Context("airframe");
  SWARMBOX_TRY(CheckConsistency(root, af));
  return af;
}

GpsAccuracy RtkAccuracy(double baseline_km) {
  const double err = kRtkConstantM + kRtkPpm * std::max(0.0, baseline_km) * 1000.0;
  return {err / kCepPerSigma, err / kR50PerSigma};
}

void SetRtkFix(GpsSpec* gps, double baseline_km) {
  const GpsAccuracy a = RtkAccuracy(baseline_km);
  gps->fix = GpsFix::kRtk;
  gps->rtk_baseline_km = baseline_km;
  gps->horizontal_std_m = a.h;
  gps->vertical_std_m = a.v;
}

Result<Airframe> LoadAirframe(const std::string& path) {
  auto doc = yaml::ParseFile(path);
  if (!doc) return doc.error();
  return ParseAirframe(*doc, path);
}

}  // namespace swarmbox::airframe
