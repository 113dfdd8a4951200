// STYLE.md 12: no allocation inside the physics step. Counts C++ heap allocations (global
// operator new, replaced in this test binary only) made by World::Step() once warm.
// (ODE's own arenas use malloc and are reused between steps; not counted here.)
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include "test_util.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace swarmbox::physics {
namespace {

TEST(StepAllocation, SteppingAWarmWorldDoesNotAllocate) {
  auto config = LoadWorld(testing::WorldPath("rubble_block"));
  ASSERT_TRUE(config.ok());
  auto world = testing::MakeWorld(*config, 3);
  const Airframe x500 = testing::LoadShippedAirframe("x500");
  const double u = x500.HoverRotorSpeed() / x500.motor.max_rot_velocity_rad_s;
  for (int i = 0; i < 20; ++i) {
    testing::Spawn(*world, testing::MakeSpawn("d" + std::to_string(i), x500, Vec3{-40.0 + 4 * i, -50, 8}, 0, u));
  }
  const Airframe x8 = testing::LoadShippedAirframe("x8_heavy");
  testing::Spawn(*world, testing::MakeSpawn("lifter", x8, Vec3{40, 40, 10}, 0,
                                            x8.HoverRotorSpeed(x8.payloads[0].mass_kg) / x8.motor.max_rot_velocity_rad_s, "stretcher", true));
  const std::vector<double> cmd(4, u);
  for (int k = 0; k < 50; ++k) world->Step();  // warm-up: ODE arenas, first contacts
  const long before = g_allocations.load();
  for (int k = 0; k < 500; ++k) {
    for (std::size_t i = 0; i < 20; ++i) ASSERT_TRUE(world->SetActuators(i, cmd).ok());
    world->Step();
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
}

}  // namespace
}  // namespace swarmbox::physics
