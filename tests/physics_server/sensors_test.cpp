// Sensor noise statistics against their configuration, the GPS error model (correlated, delayed)
// and GPS dropout.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "sensor_models.hpp"  // physics_server/src: IsaPressurePa
#include "test_util.hpp"

namespace swarmbox::physics {
namespace {

using testing::CalmWorld;
using testing::LoadShippedAirframe;
using testing::MakeWorld;
using testing::Spawn;

constexpr double kG = 9.80665;

struct Stats {
  double n = 0, sum = 0, sum2 = 0;
  void Add(double v) {
    n += 1;
    sum += v;
    sum2 += v * v;
  }
  double mean() const { return sum / n; }
  double std() const { return std::sqrt(std::max(0.0, sum2 / n - mean() * mean())); }
};

// 100 pinned (perfectly still), level x500s sampled for 10 s; bias random walks off so that the
// bias is constant per drone.
class SensorNoise : public ::testing::Test {
 protected:
  static constexpr int kDrones = 100;
  void SetUp() override {
    af_ = LoadShippedAirframe("x500");
    af_.imu.accel_bias_walk_std_m_s2 = 0;
    af_.imu.gyro_bias_walk_std_rad_s = 0;
    world_ = MakeWorld(CalmWorld(), 1234);
    for (int i = 0; i < kDrones; ++i) {
      const auto d = Spawn(*world_, testing::MakeSpawn("d" + std::to_string(i), af_, Vec3{static_cast<double>(i % 10) * 3, static_cast<double>(i / 10) * 3, 10}));
      world_->SetPinned(d, true);
    }
  }
  Airframe af_;
  std::unique_ptr<World> world_;
};

TEST_F(SensorNoise, StatisticsMatchTheirConfiguration) {
  std::vector<Stats> ax(kDrones), gz(kDrones), az(kDrones);
  Stats accel_resid, gyro_resid, baro, gps_x, gps_z, mag;
  int imu_fresh = 0, gps_fresh = 0, baro_fresh = 0;
  const double true_p = IsaPressurePa(world_->config().home_alt_m + 10 + af_.base_height_m);
  for (int k = 0; k < 2500; ++k) {
    world_->Step();
    for (std::size_t i = 0; i < kDrones; ++i) {
      const SensorSample& s = world_->sensors(i);
      const DroneTruth t = world_->Truth(i);
      if (s.imu.fresh) {
        ++imu_fresh;
        ax[i].Add(s.imu.accel_m_s2.x);
        az[i].Add(s.imu.accel_m_s2.z);
        gz[i].Add(s.imu.gyro_rad_s.z);
      }
      if (s.baro.fresh) {
        ++baro_fresh;
        baro.Add(s.baro.pressure_pa - IsaPressurePa(world_->config().home_alt_m + t.position_m.z));
      }
      if (s.gps.fresh) {
        ++gps_fresh;
        ASSERT_TRUE(s.gps.valid);
        gps_x.Add(s.gps.position_m.x - t.position_m.x);
        gps_z.Add(s.gps.position_m.z - t.position_m.z);
      }
      if (s.mag.fresh) mag.Add(s.mag.field_gauss.y - world_->config().magnetic_field_gauss.y);
    }
  }
  // Rates: 2500 steps of 4 ms = 10 s per drone.
  EXPECT_EQ(imu_fresh, kDrones * 2500);  // 250 Hz
  EXPECT_EQ(baro_fresh, kDrones * 500);  // 50 Hz
  EXPECT_EQ(gps_fresh, kDrones * 100);   // 10 Hz
  (void)true_p;

  Stats bias_x, bias_gz;
  for (int i = 0; i < kDrones; ++i) {
    bias_x.Add(ax[static_cast<std::size_t>(i)].mean());
    bias_gz.Add(gz[static_cast<std::size_t>(i)].mean());
    accel_resid.Add(ax[static_cast<std::size_t>(i)].std());
    gyro_resid.Add(gz[static_cast<std::size_t>(i)].std());
    // Level and still: the accelerometer reads +g up (plus its bias, |bias| < 5 sigma).
    EXPECT_NEAR(az[static_cast<std::size_t>(i)].mean(), kG, 5 * af_.imu.accel_bias_std_m_s2);
  }
  // White noise: 2500 samples per drone, 100 drones. The standard error of a std estimate is
  // std / sqrt(2 n) = 0.14% here; 3% leaves >10 sigma.
  EXPECT_NEAR(accel_resid.mean(), af_.imu.accel_noise_std_m_s2, 0.03 * af_.imu.accel_noise_std_m_s2);
  EXPECT_NEAR(gyro_resid.mean(), af_.imu.gyro_noise_std_rad_s, 0.03 * af_.imu.gyro_noise_std_rad_s);
  // Biases: one draw per drone, 100 drones: standard error of the std 7%; allow 25% (3.5 sigma),
  // and a mean within 4 standard errors (sigma / 10) of zero.
  EXPECT_NEAR(bias_x.std(), af_.imu.accel_bias_std_m_s2, 0.25 * af_.imu.accel_bias_std_m_s2);
  EXPECT_NEAR(bias_x.mean(), 0.0, 0.4 * af_.imu.accel_bias_std_m_s2);
  EXPECT_NEAR(bias_gz.std(), af_.imu.gyro_bias_std_rad_s, 0.25 * af_.imu.gyro_bias_std_rad_s);
  // 50 000 baro, 100 000 mag samples: std errors below 0.7%; allow 3%.
  EXPECT_NEAR(baro.std(), af_.baro.noise_std_pa, 0.03 * af_.baro.noise_std_pa);
  EXPECT_NEAR(baro.mean(), 0.0, 0.05);
  // GPS: the error is mostly a slow offset, one draw per drone over 10 s: 100 drones give the
  // total std to ~7% (1 sigma) and its mean to sigma / 10; allow 25% and 3.5 standard errors.
  EXPECT_NEAR(gps_x.std(), af_.gps.horizontal_std_m, 0.25 * af_.gps.horizontal_std_m);
  EXPECT_NEAR(gps_z.std(), af_.gps.vertical_std_m, 0.25 * af_.gps.vertical_std_m);
  EXPECT_NEAR(gps_x.mean(), 0.0, 0.35 * af_.gps.horizontal_std_m);
  EXPECT_NEAR(mag.std(), af_.mag.noise_std_gauss, 0.03 * af_.mag.noise_std_gauss);
}

// The GPS error model alone: 400 independent receivers at 10 Hz for 120 s.
class GpsError : public ::testing::Test {
 protected:
  static constexpr int kReceivers = 400;
  static constexpr int kFixes = 1200;
  static constexpr double kDt = 0.1;
  // e[r][k]: east error of receiver r at fix k; u: its up error.
  void Run(const GpsErrorModel::Split& split) {
    e_.assign(kReceivers, std::vector<double>(kFixes));
    u_.assign(kReceivers, std::vector<double>(kFixes));
    for (int r = 0; r < kReceivers; ++r) {
      GpsErrorModel m(MixSeed(77, static_cast<std::uint64_t>(r)));
      for (int k = 0; k < kFixes; ++k) {
        const Vec3 err = m.Next(k == 0 ? 0.0 : kDt, split);
        e_[static_cast<std::size_t>(r)][static_cast<std::size_t>(k)] = err.x;
        u_[static_cast<std::size_t>(r)][static_cast<std::size_t>(k)] = err.z;
      }
    }
  }
  // Std of x[k + lag] - x[k] over all receivers and k.
  static double LagStd(const std::vector<std::vector<double>>& x, int lag) {
    Stats s;
    for (const auto& series : x) {
      for (std::size_t k = 0; k + static_cast<std::size_t>(lag) < series.size(); k += 10) {
        s.Add(series[k + static_cast<std::size_t>(lag)] - series[k]);
      }
    }
    return s.std();
  }
  static double TotalStd(const std::vector<std::vector<double>>& x) {
    Stats s;
    for (const auto& series : x) {
      for (std::size_t k = 0; k < series.size(); k += 50) s.Add(series[k]);
    }
    return s.std();
  }
  std::vector<std::vector<double>> e_, u_;
};

TEST_F(GpsError, SplitKeepsTheAirframesTotalAccuracy) {
  const auto s = GpsErrorModel::SplitFor(0.8, 1.5);
  EXPECT_NEAR(std::hypot(s.slow_h, s.wander_h, s.white_h), 0.8, 1e-12);
  EXPECT_NEAR(std::hypot(s.slow_v, s.wander_v, s.white_v), 1.5, 1e-12);
  EXPECT_DOUBLE_EQ(s.white_h, GpsErrorModel::kWhiteHStdM);
  EXPECT_DOUBLE_EQ(s.wander_v, GpsErrorModel::kWanderVStdM);
  // A receiver tighter than the wander and noise alone: those scale down, no slow offset.
  const auto fine = GpsErrorModel::SplitFor(0.1, 0.2);
  EXPECT_EQ(fine.slow_h, 0.0);
  EXPECT_NEAR(std::hypot(fine.wander_h, fine.white_h), 0.1, 1e-12);
  EXPECT_NEAR(fine.white_h / fine.wander_h, GpsErrorModel::kWhiteHStdM / GpsErrorModel::kWanderHStdM, 1e-12);
}

TEST_F(GpsError, IsCorrelatedLikeARealReceiverNotWhite) {
  const auto split = GpsErrorModel::SplitFor(0.8, 1.5);
  Run(split);
  // Stationary from the first fix: the total std is the airframe's (400 slow-offset draws: the
  // std is known to ~4%; allow 12%).
  EXPECT_NEAR(TotalStd(e_), 0.8, 0.12 * 0.8);
  EXPECT_NEAR(TotalStd(u_), 1.5, 0.12 * 1.5);
  // Fix to fix, only the white part changes (the correlated part moves by < 1 cm in 0.1 s).
  const auto expected_lag = [&](double lag_s, double slow, double wander, double white) {
    return std::sqrt(2.0 * (white * white + wander * wander * (1.0 - std::exp(-lag_s / GpsErrorModel::kWanderTimeS)) +
                            slow * slow * (1.0 - std::exp(-lag_s / GpsErrorModel::kSlowTimeS))));
  };
  EXPECT_NEAR(LagStd(e_, 1), expected_lag(0.1, split.slow_h, split.wander_h, split.white_h), 0.05 * std::sqrt(2.0) * split.white_h);
  // Over 60 s the wander decorrelates (1 - 1/e) and the slow offset hardly moves: the
  // correlation times show in the growth of the difference (some 100 000 pairs: ~1% errors).
  EXPECT_NEAR(LagStd(e_, 600), expected_lag(60.0, split.slow_h, split.wander_h, split.white_h),
              0.05 * expected_lag(60.0, split.slow_h, split.wander_h, split.white_h));
  EXPECT_NEAR(LagStd(u_, 600), expected_lag(60.0, split.slow_v, split.wander_v, split.white_v),
              0.05 * expected_lag(60.0, split.slow_v, split.wander_v, split.white_v));
  // White noise would give sqrt(2) * 0.8 = 1.13 m for any lag; this receiver moves ~0.4 m a minute.
  EXPECT_LT(LagStd(e_, 600), 0.5);
}

TEST_F(GpsError, DegradedAccuracyScalesEveryComponent) {
  const auto nominal = GpsErrorModel::SplitFor(0.8, 1.5);
  const auto degraded = GpsErrorModel::Scaled(nominal, 5.0, 2.0);
  EXPECT_DOUBLE_EQ(degraded.white_h, 5.0 * nominal.white_h);
  EXPECT_DOUBLE_EQ(degraded.wander_v, 2.0 * nominal.wander_v);
  Run(degraded);
  EXPECT_NEAR(TotalStd(e_), 4.0, 0.12 * 4.0);
  EXPECT_NEAR(TotalStd(u_), 3.0, 0.12 * 3.0);
}

TEST_F(GpsError, StandaloneSpecKeepsItsSplit) {
  // `fix: standalone` (the default) is the model above, unchanged: the split of the airframe's
  // total, and the same draws from the same seed.
  GpsSpec spec;
  spec.horizontal_std_m = 0.8;
  spec.vertical_std_m = 1.5;
  const auto a = GpsErrorModel::SplitForSpec(spec);
  const auto b = GpsErrorModel::SplitFor(0.8, 1.5);
  EXPECT_EQ(a.slow_h, b.slow_h);
  EXPECT_EQ(a.wander_h, b.wander_h);
  EXPECT_EQ(a.white_h, b.white_h);
  EXPECT_EQ(a.slow_v, b.slow_v);
  EXPECT_EQ(a.wander_v, b.wander_v);
  EXPECT_EQ(a.white_v, b.white_v);
  GpsErrorModel m1(99), m2(99);
  for (int k = 0; k < 50; ++k) {
    const Vec3 e1 = m1.Next(0.1, a), e2 = m2.Next(0.1, b);
    EXPECT_EQ(e1.x, e2.x);
    EXPECT_EQ(e1.z, e2.z);
  }
}

TEST_F(GpsError, RtkSplitIsTheF9pDatasheetAccuracy) {
  // ZED-F9P: 0.01 m + 1 ppm CEP horizontally, R50 vertically. At 1 km: 0.011 m.
  const auto acc = GpsErrorModel::RtkAccuracy(1.0);
  EXPECT_NEAR(acc.h, 0.011 / 1.1774, 1e-9);  // 0.0093 m per axis
  EXPECT_NEAR(acc.v, 0.011 / 0.6745, 1e-9);  // 0.0163 m
  const auto s = GpsErrorModel::RtkSplit(1.0);
  EXPECT_NEAR(std::hypot(s.slow_h, s.wander_h, s.white_h), acc.h, 1e-12);
  EXPECT_NEAR(std::hypot(s.slow_v, s.wander_v, s.white_v), acc.v, 1e-12);
  // White small, the baseline term slow: at 1 km the ppm part is 0.0039 m per axis, at 10 km
  // (0.02 m CEP) most of the error.
  EXPECT_LT(s.white_h, 0.5 * acc.h);
  EXPECT_NEAR(s.slow_h, std::sqrt(acc.h * acc.h - 0.01 / 1.1774 * 0.01 / 1.1774), 1e-12);
  const auto far = GpsErrorModel::RtkSplit(10.0);
  EXPECT_NEAR(std::hypot(far.slow_h, far.wander_h, far.white_h), 0.02 / 1.1774, 1e-12);
  EXPECT_GT(far.slow_h, far.wander_h);
  EXPECT_EQ(far.white_h, s.white_h);
  // The spec the airframe parser builds for `fix: rtk` reports that accuracy and uses that split.
  GpsSpec spec;
  SetRtkFix(&spec, 1.0);
  EXPECT_EQ(spec.fix, GpsFix::kRtk);
  EXPECT_NEAR(spec.horizontal_std_m, acc.h, 1e-12);
  EXPECT_NEAR(spec.vertical_std_m, acc.v, 1e-12);
  EXPECT_EQ(GpsErrorModel::SplitForSpec(spec).slow_h, s.slow_h);
}

TEST_F(GpsError, RtkFixedStatisticsMatchTheDatasheet) {
  const auto split = GpsErrorModel::RtkSplit(1.0);
  const auto acc = GpsErrorModel::RtkAccuracy(1.0);
  Run(split);
  // Per-axis std over 400 receivers x 120 s: the datasheet's 0.0093 m / 0.0163 m (12%: the slow
  // part is 400 draws).
  EXPECT_NEAR(TotalStd(e_), acc.h, 0.12 * acc.h);
  EXPECT_NEAR(TotalStd(u_), acc.v, 0.12 * acc.v);
  // Vertical R50 (median |error|) as the datasheet states it: 0.011 m.
  std::vector<double> abs_u;
  for (const auto& series : u_) {
    for (std::size_t k = 0; k < series.size(); k += 50) abs_u.push_back(std::abs(series[k]));
  }
  std::nth_element(abs_u.begin(), abs_u.begin() + static_cast<std::ptrdiff_t>(abs_u.size() / 2), abs_u.end());
  EXPECT_NEAR(abs_u[abs_u.size() / 2], 0.011, 0.15 * 0.011);
  // Time-correlated as real RTK error: fix to fix only the 4 mm white part changes, so the
  // difference is far below the sqrt(2) * 9.3 mm of white noise.
  EXPECT_NEAR(LagStd(e_, 1), std::sqrt(2.0) * split.white_h, 0.05 * std::sqrt(2.0) * split.white_h);
  EXPECT_LT(LagStd(e_, 1), 0.5 * std::sqrt(2.0) * acc.h);
  // Over 60 s the multipath wander decorrelates, the baseline term hardly moves.
  const double wander_part = 1.0 - std::exp(-60.0 / GpsErrorModel::kWanderTimeS);
  const double slow_part = 1.0 - std::exp(-60.0 / GpsErrorModel::kSlowTimeS);
  const double lag60 = std::sqrt(2.0 * (split.white_h * split.white_h +
                                        split.wander_h * split.wander_h * wander_part +
                                        split.slow_h * split.slow_h * slow_part));
  EXPECT_NEAR(LagStd(e_, 600), lag60, 0.05 * lag60);
}

TEST(Sensors, RtkReceiverReportsItsAccuracyAndStaysWithinCentimetres) {
  // A pinned x500 whose GPS is an RTK-fixed F9P 1 km from its base: every fix reports the
  // datasheet accuracy (eph/epv) and lies within 5 sigma of the truth of its epoch.
  Airframe af = LoadShippedAirframe("x500");
  SetRtkFix(&af.gps, 1.0);
  auto world = MakeWorld(CalmWorld(), 5);
  const auto d = Spawn(*world, testing::MakeSpawn("rtk", af, Vec3{0, 0, 10}));
  world->SetPinned(d, true);
  const auto acc = GpsErrorModel::RtkAccuracy(1.0);
  Stats ex, ez;
  int fixes = 0;
  for (int i = 0; i < 250 * 60; ++i) {
    world->Step();
    const GpsSample& g = world->sensors(d).gps;
    if (!g.fresh || !g.valid) continue;
    ++fixes;
    EXPECT_NEAR(g.h_acc_m, acc.h, 1e-12);
    EXPECT_NEAR(g.v_acc_m, acc.v, 1e-12);
    const Vec3 p = world->Truth(d).position_m;
    ex.Add(g.position_m.x - p.x);
    ez.Add(g.position_m.z - p.z);
    EXPECT_LT(std::abs(g.position_m.x - p.x), 5.0 * acc.h);
    EXPECT_LT(std::abs(g.position_m.z - p.z), 5.0 * acc.v);
  }
  EXPECT_NEAR(fixes, 600, 2);  // 10 Hz for 60 s
  // One receiver over a minute sees its slow part as an offset: the spread about it is the white
  // and wander parts only, below the total.
  EXPECT_LT(ex.std(), acc.h);
  EXPECT_LT(ez.std(), acc.v);
}

TEST(Sensors, GpsFixesReportWhereTheDroneWasOneLatencyAgo) {
  // Noise-free GPS on a drone flying east at 5 m/s: each fix is the truth of kGpsLatencyS ago,
  // position and velocity (the velocity steps from 0 to 5 m/s at t = 1 s).
  Airframe af = LoadShippedAirframe("x500");
  af.gps.horizontal_std_m = 0;
  af.gps.vertical_std_m = 0;
  af.gps.velocity_std_m_s = 0;
  const WorldConfig world = CalmWorld();
  SensorSuite suite(af, world, 5);
  SensorSample out;
  int fixes = 0;
  for (int k = 0; k < 750; ++k) {  // 3 s at 250 Hz
    const std::int64_t t_ns = k * 4'000'000LL;
    const double t = static_cast<double>(t_ns) * 1e-9;
    TrueKinematics truth;
    truth.position_m = Vec3{t < 1.0 ? 0.0 : 5.0 * (t - 1.0), 2.0, 10.0};
    truth.velocity_m_s = Vec3{t < 1.0 ? 0.0 : 5.0, 0.0, 0.0};
    suite.Sample(t_ns, truth, false, &out);
    if (!out.gps.fresh || t < 1.5) continue;
    ++fixes;
    EXPECT_NEAR(out.gps.position_m.x, 5.0 * (t - kGpsLatencyS - 1.0), 1e-9) << "t=" << t;
    EXPECT_NEAR(out.gps.position_m.y, 2.0, 1e-12);
    EXPECT_NEAR(out.gps.velocity_m_s.x, 5.0, 1e-12);
  }
  EXPECT_EQ(fixes, 15);
}

TEST(Sensors, GpsDropoutProducesInvalidSamples) {
  auto world = MakeWorld(CalmWorld());
  const auto d = Spawn(*world, testing::MakeSpawn("d", LoadShippedAirframe("x500")));
  world->SetGpsDropout(d, true);
  int invalid = 0, valid = 0;
  for (int k = 0; k < 250; ++k) {
    world->Step();
    const GpsSample& g = world->sensors(d).gps;
    if (g.fresh) {
      EXPECT_FALSE(g.valid);
      EXPECT_EQ(g.fix_type, 0);
      ++invalid;
    }
  }
  world->SetGpsDropout(d, false);
  for (int k = 0; k < 250; ++k) {
    world->Step();
    const GpsSample& g = world->sensors(d).gps;
    if (g.fresh) {
      EXPECT_TRUE(g.valid);
      EXPECT_EQ(g.fix_type, 3);
      ++valid;
    }
  }
  EXPECT_EQ(invalid, 10);  // 10 Hz for 1 s: reports keep coming, without a fix
  EXPECT_EQ(valid, 10);
}

TEST(Sensors, BaroAltitudeTracksHeightAboveOrigin) {
  auto world = MakeWorld(CalmWorld());
  Airframe af = LoadShippedAirframe("x500");
  af.baro.noise_std_pa = 0;
  const auto d = Spawn(*world, testing::MakeSpawn("d", af, Vec3{0, 0, 40}));
  world->SetPinned(d, true);
  world->Step();
  // Noise-free ISA round trip: exact to 1 mm.
  EXPECT_NEAR(world->sensors(d).baro.altitude_m, 40 + af.base_height_m, 1e-3);
}

TEST(Sensors, MagnetometerRotatesWithYaw) {
  auto world = MakeWorld(CalmWorld());
  Airframe af = LoadShippedAirframe("x500");
  af.mag.noise_std_gauss = 0;
  const auto d = Spawn(*world, testing::MakeSpawn("d", af, Vec3{}, 1.5707963267948966));
  // Nose north: the northward field (0.21) lies along body +x; the vertical stays -0.42.
  EXPECT_NEAR(world->sensors(d).mag.field_gauss.x, 0.21, 1e-9);
  EXPECT_NEAR(world->sensors(d).mag.field_gauss.y, 0.0, 1e-9);
  EXPECT_NEAR(world->sensors(d).mag.field_gauss.z, -0.42, 1e-9);
}

}  // namespace
}  // namespace swarmbox::physics
