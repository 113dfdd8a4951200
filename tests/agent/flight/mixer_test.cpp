// Mixer: allocation from rotor geometry for the x500 quad X and the x8_heavy coaxial X8.
#include "swarmbox/flight/mixer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace swarmbox::flight {
namespace {

constexpr double kK = 8.54858e-06;
constexpr double kKm = 0.016;
constexpr double kWmax = 1000.0;

RotorGeometry Rotor(double x, double y, double z, int dir, double k = kK, double km = kKm, double wmax = kWmax) {
  RotorGeometry r;
  r.pos_m = Vec3(x, y, z);
  r.spin_dir = dir;
  r.motor_constant = k;
  r.moment_constant = km;
  r.max_rot_velocity = wmax;
  return r;
}

// PX4 x500 order: front right ccw, rear left ccw, front left cw, rear right cw.
std::vector<RotorGeometry> QuadX() {
  return {Rotor(0.174, -0.174, 0.06, 1), Rotor(-0.174, 0.174, 0.06, 1), Rotor(0.174, 0.174, 0.06, -1),
          Rotor(-0.174, -0.174, 0.06, -1)};
}

std::vector<RotorGeometry> OctoCoax() {
  const double k = 5.56e-3, km = 0.04, w = 300.0, a = 1.131;
  return {Rotor(a, -a, 0.25, 1, k, km, w),   Rotor(a, a, 0.25, -1, k, km, w),
          Rotor(-a, a, 0.25, 1, k, km, w),   Rotor(-a, -a, 0.25, -1, k, km, w),
          Rotor(a, a, -0.05, 1, k, km, w),   Rotor(a, -a, -0.05, -1, k, km, w),
          Rotor(-a, -a, -0.05, 1, k, km, w), Rotor(-a, a, -0.05, -1, k, km, w)};
}

// What the rotors really produce for commands u (the physics model), (roll, pitch, yaw, thrust).
Eigen::Vector4d Produced(const std::vector<RotorGeometry>& rotors, const MixerOutput& out) {
  Eigen::Vector4d w = Eigen::Vector4d::Zero();
  for (std::size_t i = 0; i < rotors.size(); ++i) {
    const RotorGeometry& r = rotors[i];
    const double omega = out.u[i] * r.max_rot_velocity;
    const double t = r.motor_constant * omega * omega;
    w(0) += r.pos_m.y() * t;
    w(1) += -r.pos_m.x() * t;
    w(2) += -r.spin_dir * r.moment_constant * t;
    w(3) += t;
  }
  return w;
}

TEST(Mixer, QuadXHoverThrustGivesEqualCommandsThatInvertTheSquareLaw) {
  auto m = Mixer::Create(QuadX());
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  const double hover_n = 2.0643 * 9.80665;
  const MixerOutput out = m->Mix(Vec3::Zero(), hover_n);
  const double expected_u = std::sqrt(hover_n / 4.0 / (kK * kWmax * kWmax));
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(out.u[i], expected_u, 1e-9) << i;
  EXPECT_NEAR(Produced(QuadX(), out)(3), hover_n, 1e-9);
}

TEST(Mixer, QuadXReproducesTorqueAndThrustWithinAuthority) {
  auto m = Mixer::Create(QuadX());
  ASSERT_TRUE(m.ok());
  const Vec3 torque(0.3, -0.2, 0.05);  // N m, well inside the x500's authority
  const MixerOutput out = m->Mix(torque, 20.0);
  const Eigen::Vector4d w = Produced(QuadX(), out);
  EXPECT_NEAR(w(0), 0.3, 1e-9);
  EXPECT_NEAR(w(1), -0.2, 1e-9);
  EXPECT_NEAR(w(2), 0.05, 1e-9);
  EXPECT_NEAR(w(3), 20.0, 1e-9);
  for (bool s : out.sat_positive) EXPECT_FALSE(s);
}

TEST(Mixer, PositiveRollTorqueSpeedsUpTheLeftSideRotors) {
  // FLU: +roll (right-handed about +x, forward) lifts the left side (+y): rotors with y > 0
  // spin faster.
  auto m = Mixer::Create(QuadX());
  ASSERT_TRUE(m.ok());
  const MixerOutput out = m->Mix(Vec3(0.2, 0.0, 0.0), 20.0);
  EXPECT_GT(out.u[2], out.u[0]);  // front left > front right
  EXPECT_GT(out.u[1], out.u[3]);  // rear left > rear right
}

TEST(Mixer, PositiveYawTorqueSpeedsUpClockwiseRotors) {
  // A cw rotor (dir -1) pushes the body counter-clockwise (+z) by reaction.
  auto m = Mixer::Create(QuadX());
  ASSERT_TRUE(m.ok());
  const MixerOutput out = m->Mix(Vec3(0.0, 0.0, 0.05), 20.0);
  EXPECT_GT(out.u[2], out.u[0]);
  EXPECT_GT(out.u[3], out.u[1]);
}

TEST(Mixer, CoaxialOctoSplitsWorkEquallyWithinACoaxialPair) {
  auto m = Mixer::Create(OctoCoax());
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  EXPECT_EQ(m->rotor_count(), 8u);
  EXPECT_NEAR(m->max_thrust_n(), 8 * 5.56e-3 * 300.0 * 300.0, 1e-6);
  const Vec3 torque(200.0, -150.0, 40.0);
  const MixerOutput out = m->Mix(torque, 1962.0);
  const Eigen::Vector4d w = Produced(OctoCoax(), out);
  EXPECT_NEAR(w(0), 200.0, 1e-6);
  EXPECT_NEAR(w(1), -150.0, 1e-6);
  EXPECT_NEAR(w(2), 40.0, 1e-6);
  EXPECT_NEAR(w(3), 1962.0, 1e-6);
  // Rotors 0 (front right upper, ccw) and 5 (front right lower, cw) share an arm: with no yaw
  // torque they would be equal; with yaw they differ by the yaw share only.
  const MixerOutput no_yaw = m->Mix(Vec3(200.0, -150.0, 0.0), 1962.0);
  EXPECT_NEAR(no_yaw.thrust_n[0], no_yaw.thrust_n[5], 1e-9);
}

TEST(Mixer, YawGivesWayFirstWhenSaturated) {
  auto m = Mixer::Create(QuadX());
  ASSERT_TRUE(m.ok());
  // Near full thrust a big yaw demand cannot fit; roll must still come through exactly.
  const double thrust = 0.85 * m->max_thrust_n();
  const MixerOutput out = m->Mix(Vec3(0.3, 0.0, 2.0), thrust);
  const Eigen::Vector4d w = Produced(QuadX(), out);
  EXPECT_NEAR(w(0), 0.3, 1e-6);
  EXPECT_LT(w(2), 2.0);
  EXPECT_TRUE(out.sat_positive[2]);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_GE(out.u[i], 0.0);
    EXPECT_LE(out.u[i], 1.0);
  }
}

TEST(Mixer, RejectsGeometryThatCannotControlYaw) {
  std::vector<RotorGeometry> same_dir = QuadX();
  for (auto& r : same_dir) r.spin_dir = 1;
  auto m = Mixer::Create(same_dir);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().message().find("rank"), std::string::npos) << m.error().message();
}

TEST(Mixer, RejectsTooFewRotors) {
  auto m = Mixer::Create({Rotor(1, 0, 0, 1), Rotor(-1, 0, 0, -1)});
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().message().find("4.."), std::string::npos) << m.error().message();
}

}  // namespace
}  // namespace swarmbox::flight
