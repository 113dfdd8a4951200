// NeighbourTable (agent/app/neighbour_table.hpp): Input::neighbours bounded to the nearest,
// sorted by name, each the newest state; updated per message in place, chosen anew only every
// reselect period or after a new drone; silent drones forgotten after the expiry.
#include "neighbour_table.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace swarmbox::agent {
namespace {

constexpr std::int64_t kMs = 1'000'000;

bus::DroneState State(const std::string& drone, std::int64_t t_ns, double x, double y = 0.0,
                      const std::string& mode = "m") {
  bus::DroneState s;
  s.drone = drone;
  s.sim_time_ns = t_ns;
  s.position_enu_m = {x, y, 10.0};
  s.mode = mode;
  return s;
}

std::vector<std::string> Names(std::span<const brain::Neighbour> list) {
  std::vector<std::string> names;
  for (const brain::Neighbour& n : list) names.push_back(n.name);
  return names;
}

const brain::Vec3 kOrigin{0.0, 0.0, 10.0};

TEST(NeighbourTable, ListsEveryDroneByNameWhileTheyFitAndIgnoresItself) {
  NeighbourTable t("scout_1", {.max_listed = 4});
  t.OnState(State("scout_3", 0, 30));
  t.OnState(State("lifter", 0, 90));
  t.OnState(State("scout_1", 0, 0));  // our own
  t.OnState(State("scout_2", 0, 60));
  EXPECT_EQ(Names(t.List(0, kOrigin)), (std::vector<std::string>{"lifter", "scout_2", "scout_3"}));
  EXPECT_EQ(t.size(), 3u);
}

TEST(NeighbourTable, KeepsTheNearestSortedByNameAndTheNewestStateOfEach) {
  // Given 10 drones at 10, 20, ... 100 m and room for 3.
  NeighbourTable t("self", {.max_listed = 3});
  for (int i = 1; i <= 10; ++i) t.OnState(State("d" + std::to_string(i), 0, 10.0 * (11 - i)));
  // The nearest: d10 (10 m), d9 (20 m), d8 (30 m), by name.
  EXPECT_EQ(Names(t.List(0, kOrigin)), (std::vector<std::string>{"d10", "d8", "d9"}));
  // A listed drone's new state shows at once; an older one, reordered, does not replace it.
  t.OnState(State("d8", 50 * kMs, 35, 0, "newer"));
  t.OnState(State("d8", 40 * kMs, 99, 0, "older"));
  auto list = t.List(4 * kMs, kOrigin);
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list[1].name, "d8");
  EXPECT_EQ(list[1].status, "newer");
  EXPECT_EQ(list[1].position_m.x, 35.0);
  EXPECT_EQ(list[1].t_ns, 50 * kMs);
  // An unlisted drone coming closer waits for the next reselection (200 ms): no per-step O(N).
  t.OnState(State("d1", 60 * kMs, 5));
  const std::uint64_t before = t.reselections();
  EXPECT_EQ(Names(t.List(100 * kMs, kOrigin)), (std::vector<std::string>{"d10", "d8", "d9"}));
  EXPECT_EQ(t.reselections(), before);
  EXPECT_EQ(Names(t.List(200 * kMs, kOrigin)), (std::vector<std::string>{"d1", "d10", "d9"}));
  EXPECT_EQ(t.reselections(), before + 1);
  // Seen from elsewhere the nearest change too (at the next reselection).
  EXPECT_EQ(Names(t.List(400 * kMs, {100.0, 0.0, 10.0})), (std::vector<std::string>{"d2", "d3", "d4"}));
}

TEST(NeighbourTable, ANewDroneIsListedAtTheNextListWhenThereIsRoom) {
  NeighbourTable t("self", {.max_listed = 8});
  t.OnState(State("a", 0, 1));
  EXPECT_EQ(Names(t.List(0, kOrigin)), std::vector<std::string>{"a"});
  t.OnState(State("b", 4 * kMs, 2));
  EXPECT_EQ(Names(t.List(4 * kMs, kOrigin)), (std::vector<std::string>{"a", "b"}));
}

TEST(NeighbourTable, ForgetsDronesSilentLongerThanTheExpiry) {
  NeighbourTable t("self", {.max_listed = 8, .expire_ns = 3000 * kMs});
  t.OnState(State("quiet", 0, 1));
  t.OnState(State("talker", 0, 2));
  for (std::int64_t ms = 200; ms <= 3200; ms += 200) t.OnState(State("talker", ms * kMs, 2));
  EXPECT_EQ(Names(t.List(3000 * kMs, kOrigin)), (std::vector<std::string>{"quiet", "talker"}));  // 3 s: not yet
  EXPECT_EQ(Names(t.List(3200 * kMs, kOrigin)), std::vector<std::string>{"talker"});
  EXPECT_EQ(t.size(), 1u);
  // Heard again: back.
  t.OnState(State("quiet", 3300 * kMs, 1));
  EXPECT_EQ(Names(t.List(3300 * kMs, kOrigin)), (std::vector<std::string>{"quiet", "talker"}));
}

TEST(NeighbourTable, HundredDronesCostOneReselectionPerPeriodNotPerStep) {
  // 100 drones broadcasting at 5 Hz, the brain every 4 ms step for 10 s: 50 reselections
  // (every 200 ms) plus the first, whatever the number of steps; the list stays at 32.
  NeighbourTable t("self", {});
  std::size_t longest = 0;
  for (std::int64_t step = 0; step < 2500; ++step) {
    const std::int64_t t_ns = step * 4 * kMs;
    for (int d = 0; d < 100; ++d) {
      if ((step + d) % 50 == 0) t.OnState(State("scout_" + std::to_string(d), t_ns, 4.0 * d, 1.0 * (d % 10)));
    }
    longest = std::max(longest, t.List(t_ns, kOrigin).size());
  }
  EXPECT_EQ(longest, 32u);
  EXPECT_EQ(t.size(), 100u);
  // New drones appear during the first 200 ms (each reselects once); then one per 200 ms.
  EXPECT_LE(t.reselections(), 50u + 51u);
  EXPECT_GE(t.reselections(), 50u);
}

}  // namespace
}  // namespace swarmbox::agent
