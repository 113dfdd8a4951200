// Sensor noise statistics against their configuration, and GPS dropout.
#include <gtest/gtest.h>

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
  // 50 000 baro, 10 000 GPS, 100 000 mag samples: std errors below 0.7%; allow 3%.
  EXPECT_NEAR(baro.std(), af_.baro.noise_std_pa, 0.03 * af_.baro.noise_std_pa);
  EXPECT_NEAR(baro.mean(), 0.0, 0.05);
  EXPECT_NEAR(gps_x.std(), af_.gps.horizontal_std_m, 0.03 * af_.gps.horizontal_std_m);
  EXPECT_NEAR(gps_z.std(), af_.gps.vertical_std_m, 0.03 * af_.gps.vertical_std_m);
  EXPECT_NEAR(gps_x.mean(), 0.0, 0.05);
  EXPECT_NEAR(mag.std(), af_.mag.noise_std_gauss, 0.03 * af_.mag.noise_std_gauss);
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
