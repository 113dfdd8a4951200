// Sensor noise models and the wind process: pure functions of the true state and a seeded
// generator (no ODE). Units and frames: see sensor_sample.hpp.
#pragma once

#include <cstdint>
#include <random>

#include "swarmbox/physics/airframe.hpp"
#include "swarmbox/physics/sensor_sample.hpp"
#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::physics {

// SplitMix64: derives independent seeds from (seed, stream).
std::uint64_t MixSeed(std::uint64_t seed, std::uint64_t stream);

// International Standard Atmosphere (troposphere).
double IsaPressurePa(double altitude_amsl_m);
double IsaAltitudeM(double pressure_pa);
double IsaTemperatureC(double altitude_amsl_m);

// What the sensors measure, noise-free, at one instant.
struct TrueKinematics {
  Vec3 position_m;        // ENU
  Vec3 velocity_m_s;      // ENU
  Vec3 accel_m_s2;        // ENU, kinematic acceleration
  Quat attitude;          // body -> world
  Vec3 body_rates_rad_s;  // body FLU
};

// One drone's sensor suite: rates, biases and noise. Sample() fills `out` with the sensors due at
// time_ns (fresh = true) and keeps the others as they were (fresh = false).
class SensorSuite {
 public:
  SensorSuite(const Airframe& airframe, const WorldConfig& world, std::uint64_t seed);

  void Sample(std::int64_t time_ns, const TrueKinematics& truth, bool gps_dropout, SensorSample* out);
  // Faults: GPS noise override (<= 0: the airframe's value) and IMU bias steps.
  void SetGpsAccuracy(double horizontal_std_m, double vertical_std_m);
  void AddImuBias(const Vec3& accel_m_s2, const Vec3& gyro_rad_s) {
    accel_bias_ += accel_m_s2;
    gyro_bias_ += gyro_rad_s;
  }

 private:
  double Gauss(double std) { return std * normal_(rng_); }
  static std::int64_t PeriodNs(double rate_hz);

  ImuSpec imu_;
  BaroSpec baro_;
  MagSpec mag_;
  GpsSpec gps_;
  GpsSpec gps_nominal_;
  const WorldConfig* world_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  Vec3 accel_bias_;
  Vec3 gyro_bias_;
  std::int64_t imu_period_ns_, baro_period_ns_, mag_period_ns_, gps_period_ns_;
  std::int64_t imu_next_ns_ = 0, baro_next_ns_ = 0, mag_next_ns_ = 0, gps_next_ns_ = 0;
};

// Mean wind plus first-order Gauss-Markov gusts per axis, advanced in fixed steps.
class WindModel {
 public:
  WindModel(const WindConfig& config, std::uint64_t seed);
  void Configure(const WindConfig& config) { config_ = config; }
  void Advance(double dt_s);
  Vec3 wind_m_s() const { return config_.mean_m_s + gust_; }

 private:
  WindConfig config_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  Vec3 gust_;
};

}  // namespace swarmbox::physics
