// CameraTrigger (camera_trigger.hpp): the fixed rate, PX4-style distance triggering with the rate
// as its upper bound, and the hover floor.
#include "camera_trigger.hpp"

#include <gtest/gtest.h>

namespace swarmbox::physics {
namespace {

constexpr std::int64_t kMs = 1'000'000;

airframe::CameraSpec Distance(double distance_m, double interval_max_s) {
  airframe::CameraSpec spec;
  spec.trigger_distance_m = distance_m;
  spec.trigger_interval_max_s = interval_max_s;
  return spec;
}

TEST(CameraTrigger, WithoutADistanceEveryRateStepTakesAFrame) {
  CameraTrigger trigger(1);
  const airframe::CameraSpec spec;  // trigger_distance_m = 0
  EXPECT_TRUE(trigger.Due(0, spec, true, 0, {0, 0, 30}));
  trigger.Captured(0, 0, {0, 0, 30});
  EXPECT_TRUE(trigger.Due(0, spec, true, 200 * kMs, {0, 0, 30}));  // not moved: still due
  EXPECT_FALSE(trigger.Due(0, spec, false, 204 * kMs, {9, 9, 30}));
}

TEST(CameraTrigger, ADroneFirstFrameIsTakenWhereverItIs) {
  CameraTrigger trigger(2);
  EXPECT_TRUE(trigger.Due(1, Distance(4.0, 0), true, 0, {0, 0, 0}));
}

TEST(CameraTrigger, AFrameOnceTheCameraMovedTheDistanceHorizontally) {
  CameraTrigger trigger(1);
  const airframe::CameraSpec spec = Distance(4.0, 0);
  trigger.Captured(0, 0, {0, 0, 30});
  // Given a drone cruising at 5 m/s along x, frames on the 5 Hz grid (1 m apart)
  EXPECT_FALSE(trigger.Due(0, spec, true, 200 * kMs, {1, 0, 30}));
  EXPECT_FALSE(trigger.Due(0, spec, true, 600 * kMs, {3, 0, 30}));
  EXPECT_TRUE(trigger.Due(0, spec, true, 800 * kMs, {4, 0, 30}));
  EXPECT_TRUE(trigger.Due(0, spec, true, 800 * kMs, {0, -4.5, 30}));  // any horizontal direction
  EXPECT_FALSE(trigger.Due(0, spec, true, 800 * kMs, {0, 0, 60}));   // a climb is not a distance
  // The rate is the upper bound: off its grid nothing is due however far it moved.
  EXPECT_FALSE(trigger.Due(0, spec, false, 804 * kMs, {40, 0, 30}));
}

TEST(CameraTrigger, DistanceIsCountedFromTheLastFrameTaken) {
  CameraTrigger trigger(1);
  const airframe::CameraSpec spec = Distance(4.0, 0);
  trigger.Captured(0, 0, {0, 0, 30});
  trigger.Captured(0, 800 * kMs, {4, 0, 30});
  EXPECT_FALSE(trigger.Due(0, spec, true, 1000 * kMs, {5, 0, 30}));
  EXPECT_TRUE(trigger.Due(0, spec, true, 1600 * kMs, {8, 0, 30}));
}

TEST(CameraTrigger, AHoveringDroneLooksAtTheFloorInterval) {
  CameraTrigger trigger(1);
  const airframe::CameraSpec spec = Distance(4.0, 1.0);
  trigger.Captured(0, 2000 * kMs, {10, 10, 30});
  EXPECT_FALSE(trigger.Due(0, spec, true, 2800 * kMs, {10.2, 10, 30}));
  EXPECT_TRUE(trigger.Due(0, spec, true, 3000 * kMs, {10.2, 10, 30}));
  // Without a floor it waits for the distance.
  EXPECT_FALSE(trigger.Due(0, Distance(4.0, 0), true, 60'000 * kMs, {10.2, 10, 30}));
}

}  // namespace
}  // namespace swarmbox::physics
