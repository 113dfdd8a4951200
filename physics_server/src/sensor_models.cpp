#include "sensor_models.hpp"

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

std::int64_t SensorSuite::PeriodNs(double rate_hz) { return static_cast<std::int64_t>(std::llround(1e9 / rate_hz)); }

SensorSuite::SensorSuite(const Airframe& airframe, const WorldConfig& world, std::uint64_t seed)
    : imu_(airframe.imu),
      baro_(airframe.baro),
      mag_(airframe.mag),
      gps_(airframe.gps),
      gps_nominal_(airframe.gps),
      world_(&world),
      rng_(seed) {
  accel_bias_ = {Gauss(imu_.accel_bias_std_m_s2), Gauss(imu_.accel_bias_std_m_s2), Gauss(imu_.accel_bias_std_m_s2)};
  gyro_bias_ = {Gauss(imu_.gyro_bias_std_rad_s), Gauss(imu_.gyro_bias_std_rad_s), Gauss(imu_.gyro_bias_std_rad_s)};
  imu_period_ns_ = PeriodNs(imu_.rate_hz);
  baro_period_ns_ = PeriodNs(baro_.rate_hz);
  mag_period_ns_ = PeriodNs(mag_.rate_hz);
  gps_period_ns_ = PeriodNs(gps_.rate_hz);
}

void SensorSuite::Sample(std::int64_t time_ns, const TrueKinematics& t, bool gps_dropout, SensorSample* out) {
  out->time_ns = time_ns;
  out->imu.fresh = out->baro.fresh = out->mag.fresh = out->gps.fresh = false;
  const double g = world_->gravity_m_s2;

  if (time_ns >= imu_next_ns_) {
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
    imu_next_ns_ += imu_period_ns_;
    if (imu_next_ns_ <= time_ns) imu_next_ns_ = time_ns + imu_period_ns_;
  }
  if (time_ns >= baro_next_ns_) {
    const double amsl = world_->home_alt_m + t.position_m.z;
    const double p = IsaPressurePa(amsl) + Gauss(baro_.noise_std_pa);
    out->baro.pressure_pa = p;
    out->baro.altitude_m = IsaAltitudeM(p) - world_->home_alt_m;
    out->baro.temperature_c = IsaTemperatureC(amsl);
    out->baro.fresh = true;
    baro_next_ns_ += baro_period_ns_;
    if (baro_next_ns_ <= time_ns) baro_next_ns_ = time_ns + baro_period_ns_;
  }
  if (time_ns >= mag_next_ns_) {
    const double n = mag_.noise_std_gauss;
    out->mag.field_gauss = RotateInverse(t.attitude, world_->magnetic_field_gauss) + Vec3{Gauss(n), Gauss(n), Gauss(n)};
    out->mag.fresh = true;
    mag_next_ns_ += mag_period_ns_;
    if (mag_next_ns_ <= time_ns) mag_next_ns_ = time_ns + mag_period_ns_;
  }
  if (time_ns >= gps_next_ns_) {
    GpsSample& gps = out->gps;
    gps.fresh = true;
    if (gps_dropout) {
      gps.valid = false;
      gps.fix_type = 0;
    } else {
      const double h = gps_.horizontal_std_m, v = gps_.vertical_std_m, s = gps_.velocity_std_m_s;
      gps.valid = true;
      gps.fix_type = 3;
      gps.position_m = t.position_m + Vec3{Gauss(h), Gauss(h), Gauss(v)};
      gps.velocity_m_s = t.velocity_m_s + Vec3{Gauss(s), Gauss(s), Gauss(s)};
      const double lat0 = world_->home_lat_deg * std::numbers::pi / 180.0;
      gps.lat_deg = world_->home_lat_deg + gps.position_m.y / kEarthRadiusM * 180.0 / std::numbers::pi;
      gps.lon_deg = world_->home_lon_deg + gps.position_m.x / (kEarthRadiusM * std::cos(lat0)) * 180.0 / std::numbers::pi;
      gps.alt_m = world_->home_alt_m + gps.position_m.z;
      gps.h_acc_m = h;
      gps.v_acc_m = v;
    }
    gps_next_ns_ += gps_period_ns_;
    if (gps_next_ns_ <= time_ns) gps_next_ns_ = time_ns + gps_period_ns_;
  }
}

void SensorSuite::SetGpsAccuracy(double horizontal_std_m, double vertical_std_m) {
  gps_.horizontal_std_m = horizontal_std_m > 0 ? horizontal_std_m : gps_nominal_.horizontal_std_m;
  gps_.vertical_std_m = vertical_std_m > 0 ? vertical_std_m : gps_nominal_.vertical_std_m;
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
