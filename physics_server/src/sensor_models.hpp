// Sensor noise models and the wind process: pure functions of the true state and a seeded
// generator (no ODE). Units and frames: see sensor_sample.hpp.
#pragma once

#include <array>
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

// GPS receiver position error, per axis (ENU), as the sum of three processes:
//  * a slow offset (ionosphere, troposphere, orbit and clock residuals): first-order Gauss-Markov,
//    correlation time kSlowTimeS = 1800 s (Joerger and Pervan's troposphere error bounds,
//    900-2700 s; the ionospheric residual of a single-frequency receiver varies as slowly);
//  * multipath and receiver wander: first-order Gauss-Markov, kWanderTimeS = 60 s (the
//    correlation time of PX4's SITL Gazebo GPS plugin, kGpsCorrelationTime; the bend of the error
//    autocorrelation of stationary receivers near one minute), std 0.5 m per pseudorange (code
//    multipath at zenith, Joerger and Pervan) times HDOP 0.7 / sqrt(2) per horizontal axis
//    = 0.25 m, times VDOP 1.1 vertically = 0.55 m (DOPs of PX4's simulated receiver);
//  * white noise per fix: 0.2 m horizontal, 0.5 m vertical (PX4's SensorGpsSim).
// The airframe's horizontal_std_m / vertical_std_m are the *total* 1-sigma per-axis error of a
// fix (a u-blox M8/M9-class receiver: 1.5-2.5 m CEP, CEP = 1.18 sigma); the slow offset takes what
// the other two leave (a spec tighter than those two scales them down, with no slow offset). A
// degraded accuracy (SetGpsAccuracy) scales the airframe's split by new / nominal. The states
// start in their stationary distribution, from their own generator. Advance once per fix; no
// allocation.
//
// RTK fixed (GpsFix::kRtk, `fix: rtk`): a u-blox ZED-F9P, the receiver of Holybro's H-RTK F9P for
// the X500, with corrections from a base station rtk_baseline_km away. Datasheet (u-blox ZED-F9P
// Data sheet, UBX-17051259, "Performance"; ZED-F9P Integration manual UBX-18010802 R13, section
// 1 / RTK performance): RTK horizontal accuracy 0.01 m + 1 ppm CEP, vertical 0.01 m + 1 ppm R50,
// navigation update rate up to 20 Hz (kRtkMaxRateHz), velocity 0.05 m/s. Per axis: a circular
// Gaussian's CEP is sqrt(2 ln 2) sigma = 1.1774 sigma, a 1-D R50 0.6745 sigma, so at 1 km
// (0.011 m) sigma_h = 0.0093 m and sigma_v = 0.0163 m (RtkAccuracy). The same three processes
// carry it, split as real RTK error is:
//  * white per fix: the carrier-phase noise of a fixed solution, ~1% of the ~0.19 m L1
//    wavelength per satellite (~2 mm) times the DOPs: kRtkWhiteHStdM = 0.004 m, kRtkWhiteVStdM
//    = 0.007 m;
//  * wander (60 s, as above): carrier-phase multipath and antenna phase-centre residuals, the
//    rest of the baseline-independent 0.01 m (0.0075 m per horizontal axis, 0.013 m vertically);
//  * slow (1800 s): the baseline term, 1 ppm of differential ionosphere/troposphere/orbit
//    residuals between base and rover, which decorrelate as slowly as the atmosphere itself;
//    it takes what the other two leave of the datasheet total (0.0039 m per axis at 1 km).
// Corrections: RTCM3 at 1 Hz over the telemetry link, so their age is ~1-2 s, within what the
// datasheet's figures assume (the F9P keeps RTK fixed with corrections up to its
// CFG-NAVSPG-CONSTR_DGNSSTO, 60 s by default); no separate age term. Latency: as the standalone
// receiver's (kGpsLatencyS: PX4 flies the F9P with the same EKF2_GPS_DELAY default).
class GpsErrorModel {
 public:
  static constexpr double kSlowTimeS = 1800.0;
  static constexpr double kWanderTimeS = 60.0;
  static constexpr double kWanderHStdM = 0.25;
  static constexpr double kWanderVStdM = 0.55;
  static constexpr double kWhiteHStdM = 0.2;
  static constexpr double kWhiteVStdM = 0.5;

  // RTK fixed: the receiver's white noise; its datasheet total is airframe::RtkAccuracy.
  static constexpr double kRtkWhiteHStdM = 0.004;
  static constexpr double kRtkWhiteVStdM = 0.007;

  struct Split {  // per-axis 1-sigma of each component for a total (h, v) accuracy [m]
    double slow_h, slow_v, wander_h, wander_v, white_h, white_v;
  };
  using Accuracy = airframe::GpsAccuracy;  // total 1-sigma per axis [m]
  // The split of an airframe's total per-axis accuracy (h, v) [m] (standalone receiver).
  static Split SplitFor(double total_h_m, double total_v_m);
  // An RTK-fixed ZED-F9P's accuracy and its split, `baseline_km` from its base.
  static Accuracy RtkAccuracy(double baseline_km) { return airframe::RtkAccuracy(baseline_km); }
  static Split RtkSplit(double baseline_km);
  // The split of a receiver as the airframe describes it (standalone or rtk).
  static Split SplitForSpec(const GpsSpec& spec);
  static Split Scaled(const Split& s, double ratio_h, double ratio_v);

  explicit GpsErrorModel(std::uint64_t seed);
  // Advances the correlated states by dt_s [s] and returns this fix's error [m] (ENU).
  Vec3 Next(double dt_s, const Split& split);
  // The correlated part (slow + wander) of the last fix [m]; the white part is not included.
  const Vec3& correlated_m() const { return correlated_; }

 private:
  double Gauss() { return normal_(rng_); }
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  Vec3 slow_unit_, wander_unit_;  // unit-variance Gauss-Markov states
  Vec3 correlated_;
};

// Latency of a GPS fix: the position and velocity it reports are those of kGpsLatencyS earlier
// (PX4's SITL Gazebo GPS plugin delays fixes by 0.12 s; PX4's EKF2_GPS_DELAY default is 110 ms;
// u-blox M8/M9 solutions come out ~0.1 s after their epoch).
inline constexpr double kGpsLatencyS = 0.12;

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
  // Sample()'s sensors, each when due; then its next time one period on (or one period from now
  // after a gap).
  static void Reschedule(std::int64_t time_ns, std::int64_t period_ns, std::int64_t* next_ns);
  void SampleImu(std::int64_t time_ns, const TrueKinematics& t, SensorSample* out);
  void SampleBaro(std::int64_t time_ns, const TrueKinematics& t, SensorSample* out);
  void SampleMag(std::int64_t time_ns, const TrueKinematics& t, SensorSample* out);
  void SampleGps(std::int64_t time_ns, bool gps_dropout, SensorSample* out);
  struct PastState {
    std::int64_t time_ns = 0;
    Vec3 position_m, velocity_m_s;
  };
  // Truth as it was kGpsLatencyS before time_ns (the oldest kept if the history is shorter).
  const PastState& Delayed(std::int64_t time_ns) const;

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
  GpsErrorModel gps_error_;
  GpsErrorModel::Split gps_split_;
  std::int64_t last_fix_ns_ = -1;
  static constexpr std::size_t kHistory = 256;  // >= latency / control period (0.12 s / 1 ms)
  std::array<PastState, kHistory> history_{};
  std::size_t history_head_ = 0;   // next slot to write
  std::size_t history_count_ = 0;
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
