#include "sensor_models.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace swarmbox::physics {
namespace {
constexpr double kP0Pa = 101325.0;
constexpr double kT0K = 288.15;
constexpr double kLapseK_m = 0.0065;
constexpr double kBaroExponent = 5.255877;  // g M / (R L)
constexpr double kEarthRadiusM = 6378137.0;
}  // namespace

std::uint64_t MixSeed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

double IsaPressurePa(double altitude_amsl_m) {
  return kP0Pa * std::pow(1.0 - kLapseK_m * altitude_amsl_m / kT0K, kBaroExponent);
}
double IsaAltitudeM(double pressure_pa) {
  return kT0K / kLapseK_m * (1.0 - std::pow(pressure_pa / kP0Pa, 1.0 / kBaroExponent));
}
double IsaTemperatureC(double altitude_amsl_m) { return kT0K - kLapseK_m * altitude_amsl_m - 273.15; }

GpsErrorModel::Split GpsErrorModel::SplitFor(double total_h_m, double total_v_m) {
  Split s{};
  const auto axis = [](double total, double wander, double white, double* slow, double* w_out, double* n_out) {
    const double fast2 = wander * wander + white * white;
    if (total * total >= fast2) {
      *slow = std::sqrt(total * total - fast2);
      *w_out = wander;
      *n_out = white;
    } else {  // a receiver better than the wander and noise alone: scale those down
      const double k = fast2 > 0.0 ? total / std::sqrt(fast2) : 0.0;
      *slow = 0.0;
      *w_out = k * wander;
      *n_out = k * white;
    }
  };
  axis(total_h_m, kWanderHStdM, kWhiteHStdM, &s.slow_h, &s.wander_h, &s.white_h);
  axis(total_v_m, kWanderVStdM, kWhiteVStdM, &s.slow_v, &s.wander_v, &s.white_v);
  return s;
}

GpsErrorModel::Split GpsErrorModel::RtkSplit(double baseline_km) {
  const Accuracy total = RtkAccuracy(baseline_km);
  const Accuracy constant = RtkAccuracy(0.0);
  Split s{};
  s.white_h = kRtkWhiteHStdM;
  s.white_v = kRtkWhiteVStdM;
  s.wander_h = std::sqrt(constant.h * constant.h - s.white_h * s.white_h);
  s.wander_v = std::sqrt(constant.v * constant.v - s.white_v * s.white_v);
  s.slow_h = std::sqrt(std::max(0.0, total.h * total.h - constant.h * constant.h));
  s.slow_v = std::sqrt(std::max(0.0, total.v * total.v - constant.v * constant.v));
  return s;
}

GpsErrorModel::Split GpsErrorModel::SplitForSpec(const GpsSpec& spec) {
  return spec.fix == GpsFix::kRtk ? RtkSplit(spec.rtk_baseline_km)
                                  : SplitFor(spec.horizontal_std_m, spec.vertical_std_m);
}

GpsErrorModel::Split GpsErrorModel::Scaled(const Split& s, double ratio_h, double ratio_v) {
  return {s.slow_h * ratio_h, s.slow_v * ratio_v, s.wander_h * ratio_h,
          s.wander_v * ratio_v, s.white_h * ratio_h, s.white_v * ratio_v};
}

GpsErrorModel::GpsErrorModel(std::uint64_t seed) : rng_(seed) {
  // Stationary start: each unit state is N(0, 1).
  slow_unit_ = {Gauss(), Gauss(), Gauss()};
  wander_unit_ = {Gauss(), Gauss(), Gauss()};
}

Vec3 GpsErrorModel::Next(double dt_s, const Split& s) {
  // Exact discretisation of a unit-variance first-order Gauss-Markov process.
  const auto advance = [this](Vec3* x, double dt, double tau) {
    const double a = std::exp(-dt / tau);
    const double q = std::sqrt(1.0 - a * a);
    *x = Vec3{a * x->x + q * Gauss(), a * x->y + q * Gauss(), a * x->z + q * Gauss()};
  };
  if (dt_s > 0.0) {
    advance(&slow_unit_, dt_s, kSlowTimeS);
    advance(&wander_unit_, dt_s, kWanderTimeS);
  }
  correlated_ = Vec3{s.slow_h * slow_unit_.x + s.wander_h * wander_unit_.x,
                     s.slow_h * slow_unit_.y + s.wander_h * wander_unit_.y,
                     s.slow_v * slow_unit_.z + s.wander_v * wander_unit_.z};
  return correlated_ + Vec3{s.white_h * Gauss(), s.white_h * Gauss(), s.white_v * Gauss()};
}

std::int64_t SensorSuite::PeriodNs(double rate_hz) { return static_cast<std::int64_t>(std::llround(1e9 / rate_hz)); }

SensorSuite::SensorSuite(const Airframe& airframe, const WorldConfig& world, std::uint64_t seed)
    : imu_(airframe.imu),
      baro_(airframe.baro),
      mag_(airframe.mag),
      gps_(airframe.gps),
      gps_nominal_(airframe.gps),
      world_(&world),
      rng_(seed),
      gps_error_(MixSeed(seed, 0x6A5)),
      gps_split_(GpsErrorModel::SplitForSpec(airframe.gps)) {
  accel_bias_ = {Gauss(imu_.accel_bias_std_m_s2), Gauss(imu_.accel_bias_std_m_s2), Gauss(imu_.accel_bias_std_m_s2)};
  gyro_bias_ = {Gauss(imu_.gyro_bias_std_rad_s), Gauss(imu_.gyro_bias_std_rad_s), Gauss(imu_.gyro_bias_std_rad_s)};
  imu_period_ns_ = PeriodNs(imu_.rate_hz);
  baro_period_ns_ = PeriodNs(baro_.rate_hz);
  mag_period_ns_ = PeriodNs(mag_.rate_hz);
  gps_period_ns_ = PeriodNs(gps_.rate_hz);
}

const SensorSuite::PastState& SensorSuite::Delayed(std::int64_t time_ns) const {
  const auto latency_ns = static_cast<std::int64_t>(std::llround(kGpsLatencyS * 1e9));
  // Newest first: the first state at or before time_ns - latency.
  std::size_t idx = (history_head_ + kHistory - 1) % kHistory;
  for (std::size_t k = 0; k + 1 < history_count_; ++k) {
    if (history_[idx].time_ns <= time_ns - latency_ns) return history_[idx];
    idx = (idx + kHistory - 1) % kHistory;
  }
  return history_[idx];  // the oldest kept
}

void SensorSuite::Sample(std::int64_t time_ns, const TrueKinematics& t, bool gps_dropout, SensorSample* out) {
  out->time_ns = time_ns;
  if (history_count_ == 0 || history_[(history_head_ + kHistory - 1) % kHistory].time_ns != time_ns) {
    history_[history_head_] = PastState{time_ns, t.position_m, t.velocity_m_s};
    history_head_ = (history_head_ + 1) % kHistory;
    history_count_ = std::min(history_count_ + 1, kHistory);
  }
  out->imu.fresh = out->baro.fresh = out->mag.fresh = out->gps.fresh = false;
  // Each sensor when it is due, in this order (the noise draws share one generator).
  if (time_ns >= imu_next_ns_) SampleImu(time_ns, t, out);
  if (time_ns >= baro_next_ns_) SampleBaro(time_ns, t, out);
  if (time_ns >= mag_next_ns_) SampleMag(time_ns, t, out);
  if (time_ns >= gps_next_ns_) SampleGps(time_ns, gps_dropout, out);
}

void SensorSuite::Reschedule(std::int64_t time_ns, std::int64_t period_ns, std::int64_t* next_ns) {
  *next_ns += period_ns;
  if (*next_ns <= time_ns) *next_ns = time_ns + period_ns;
}

void SensorSuite::SampleImu(std::int64_t time_ns, const TrueKinematics& t, SensorSample* out) {
  const double g = world_->gravity_m_s2;
  const double dt_s = static_cast<double>(imu_period_ns_) * 1e-9;
  const double aw = imu_.accel_bias_walk_std_m_s2 * std::sqrt(dt_s);
  const double gw = imu_.gyro_bias_walk_std_rad_s * std::sqrt(dt_s);
  accel_bias_ += Vec3{Gauss(aw), Gauss(aw), Gauss(aw)};
  gyro_bias_ += Vec3{Gauss(gw), Gauss(gw), Gauss(gw)};
  const Vec3 specific = RotateInverse(t.attitude, t.accel_m_s2 + Vec3{0, 0, g});
  const double an = imu_.accel_noise_std_m_s2, gn = imu_.gyro_noise_std_rad_s;
  out->imu.accel_m_s2 = specific + accel_bias_ + Vec3{Gauss(an), Gauss(an), Gauss(an)};
  out->imu.gyro_rad_s = t.body_rates_rad_s + gyro_bias_ + Vec3{Gauss(gn), Gauss(gn), Gauss(gn)};
  out->imu.fresh = true;
  Reschedule(time_ns, imu_period_ns_, &imu_next_ns_);
}

void SensorSuite::SampleBaro(std::int64_t time_ns, const TrueKinematics& t, SensorSample* out) {
  const double amsl = world_->home_alt_m + t.position_m.z;
  const double p = IsaPressurePa(amsl) + Gauss(baro_.noise_std_pa);
  out->baro.pressure_pa = p;
  out->baro.altitude_m = IsaAltitudeM(p) - world_->home_alt_m;
  out->baro.temperature_c = IsaTemperatureC(amsl);
  out->baro.fresh = true;
  Reschedule(time_ns, baro_period_ns_, &baro_next_ns_);
}

void SensorSuite::SampleMag(std::int64_t time_ns, const TrueKinematics& t, SensorSample* out) {
  const double n = mag_.noise_std_gauss;
  out->mag.field_gauss = RotateInverse(t.attitude, world_->magnetic_field_gauss) + Vec3{Gauss(n), Gauss(n), Gauss(n)};
  out->mag.fresh = true;
  Reschedule(time_ns, mag_period_ns_, &mag_next_ns_);
}

void SensorSuite::SampleGps(std::int64_t time_ns, bool gps_dropout, SensorSample* out) {
  GpsSample& gps = out->gps;
  gps.fresh = true;
  if (gps_dropout) {
    gps.valid = false;
    gps.fix_type = 0;
  } else {
    const double h = gps_.horizontal_std_m, v = gps_.vertical_std_m, s = gps_.velocity_std_m_s;
    const double dt_s = last_fix_ns_ < 0 ? 0.0 : static_cast<double>(time_ns - last_fix_ns_) * 1e-9;
    last_fix_ns_ = time_ns;
    const PastState& past = Delayed(time_ns);
    gps.valid = true;
    gps.fix_type = 3;
    gps.position_m = past.position_m + gps_error_.Next(dt_s, gps_split_);
    gps.velocity_m_s = past.velocity_m_s + Vec3{Gauss(s), Gauss(s), Gauss(s)};
    const double lat0 = world_->home_lat_deg * std::numbers::pi / 180.0;
    gps.lat_deg = world_->home_lat_deg + gps.position_m.y / kEarthRadiusM * 180.0 / std::numbers::pi;
    gps.lon_deg = world_->home_lon_deg + gps.position_m.x / (kEarthRadiusM * std::cos(lat0)) * 180.0 / std::numbers::pi;
    gps.alt_m = world_->home_alt_m + gps.position_m.z;
    gps.h_acc_m = h;
    gps.v_acc_m = v;
  }
  Reschedule(time_ns, gps_period_ns_, &gps_next_ns_);
}

void SensorSuite::SetGpsAccuracy(double horizontal_std_m, double vertical_std_m) {
  gps_.horizontal_std_m = horizontal_std_m > 0 ? horizontal_std_m : gps_nominal_.horizontal_std_m;
  gps_.vertical_std_m = vertical_std_m > 0 ? vertical_std_m : gps_nominal_.vertical_std_m;
  // Degraded: the airframe's split scaled (an airframe without GPS noise: split afresh).
  const double nh = gps_nominal_.horizontal_std_m, nv = gps_nominal_.vertical_std_m;
  if (nh > 0 && nv > 0) {
    gps_split_ = GpsErrorModel::Scaled(GpsErrorModel::SplitForSpec(gps_nominal_), gps_.horizontal_std_m / nh,
                                       gps_.vertical_std_m / nv);
  } else {
    gps_split_ = GpsErrorModel::SplitFor(gps_.horizontal_std_m, gps_.vertical_std_m);
  }
}

WindModel::WindModel(const WindConfig& config, std::uint64_t seed) : config_(config), rng_(seed) {}

void WindModel::Advance(double dt_s) {
  if (config_.gust_std_m_s <= 0) {
    gust_ = {};
    return;
  }
  const double a = std::exp(-dt_s / config_.gust_time_s);
  const double s = config_.gust_std_m_s * std::sqrt(1.0 - a * a);
  gust_ = Vec3{gust_.x * a + s * normal_(rng_), gust_.y * a + s * normal_(rng_), gust_.z * a + 0.3 * s * normal_(rng_)};
}

}  // namespace swarmbox::physics
