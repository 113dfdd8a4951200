// Search geometry (agent/swarm/search_pattern.hpp): footprint, partition, lawnmower, orbit.
#include "swarmbox/swarm/search_pattern.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace swarmbox::swarm {
namespace {

using V2 = Eigen::Vector2d;

TEST(SearchPattern, FootprintFollowsThePinholeModel) {
  // across = 2 h tan(hfov/2); along = across * height/width.
  const CameraFootprint fp = GroundFootprint(30.0, 1.2, 320, 240);
  EXPECT_NEAR(fp.across_m, 2 * 30.0 * std::tan(0.6), 1e-9);
  EXPECT_NEAR(fp.along_m, fp.across_m * 0.75, 1e-9);
  EXPECT_NEAR(SweepSpacing(fp, 0.2), 0.8 * fp.across_m, 1e-9);
}

TEST(SearchPattern, PartitionCoversTheAreaWithDisjointStripsAcrossTheLongerSide) {
  const Rect area{-100, -50, 100, 50};  // 200 x 100: strips split x
  const std::vector<std::string> names = {"a", "b", "c"};
  const std::vector<raft::Sector> s = PartitionArea(area, names);
  ASSERT_EQ(s.size(), 3u);
  double total = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(s[i].drone, names[i]);
    EXPECT_DOUBLE_EQ(s[i].y_min_m, -50);
    EXPECT_DOUBLE_EQ(s[i].y_max_m, 50);
    EXPECT_NEAR(s[i].x_max_m - s[i].x_min_m, 200.0 / 3, 1e-9);
    if (i > 0) {
      EXPECT_DOUBLE_EQ(s[i].x_min_m, s[i - 1].x_max_m);  // adjacent, no gap
    }
    total += (s[i].x_max_m - s[i].x_min_m) * (s[i].y_max_m - s[i].y_min_m);
  }
  EXPECT_DOUBLE_EQ(s.front().x_min_m, -100);
  EXPECT_DOUBLE_EQ(s.back().x_max_m, 100);
  EXPECT_NEAR(total, 200.0 * 100.0, 1e-6);
  EXPECT_TRUE(PartitionArea(area, std::vector<std::string>{}).empty());
}

// Coverage: every ground point of the sector lies within half a swath of some lane (the lanes are
// at most `spacing` apart), checked on a 1 m grid.
TEST(SearchPattern, LawnmowerSwathsCoverTheSector) {
  const Rect sector{0, 0, 60, 150};  // lanes along y (the longer side)
  const CameraFootprint fp = GroundFootprint(30.0, 1.2, 320, 240);
  const double spacing = SweepSpacing(fp, 0.2);
  const std::vector<Waypoint> w = LawnmowerWaypoints(sector, spacing, 30.0, fp, V2(0, 0));
  ASSERT_EQ(w.size() % 2, 0u);
  const int lanes = static_cast<int>(w.size() / 2);
  EXPECT_EQ(lanes, static_cast<int>(std::ceil(60.0 / spacing)));
  for (const Waypoint& p : w) {
    EXPECT_TRUE(sector.Contains(p.position_m.head<2>()));
    EXPECT_DOUBLE_EQ(p.position_m.z(), 30.0);
  }
  // Starts at the corner nearest (0, 0), nose along the first lane (north: yaw pi/2).
  EXPECT_LT(w.front().position_m.head<2>().norm(), 40.0);
  EXPECT_NEAR(w.front().yaw_rad, std::numbers::pi / 2, 1e-12);
  // Alternating directions.
  EXPECT_GT(w[1].position_m.y(), w[0].position_m.y());
  ASSERT_GT(lanes, 1);
  EXPECT_LT(w[3].position_m.y(), w[2].position_m.y());
  for (double x = 0; x <= 60; x += 1.0) {
    for (double y = 0; y <= 150; y += 1.0) {
      bool covered = false;
      for (int l = 0; l < lanes && !covered; ++l) {
        const double lane_x = w[static_cast<std::size_t>(2 * l)].position_m.x();
        const double y0 = std::min(w[static_cast<std::size_t>(2 * l)].position_m.y(), w[static_cast<std::size_t>(2 * l + 1)].position_m.y());
        const double y1 = std::max(w[static_cast<std::size_t>(2 * l)].position_m.y(), w[static_cast<std::size_t>(2 * l + 1)].position_m.y());
        covered = std::abs(x - lane_x) <= fp.across_m / 2 && y >= y0 - fp.along_m / 2 - 1e-9 &&
                  y <= y1 + fp.along_m / 2 + 1e-9;
      }
      ASSERT_TRUE(covered) << "(" << x << ", " << y << ") not seen";
    }
  }
}

TEST(SearchPattern, OrbitWaypointsCircleTheTargetFacingIt) {
  const std::vector<Waypoint> o = OrbitWaypoints(V2(10, -5), 15.0, 30.0, 8, 0.0);
  ASSERT_EQ(o.size(), 8u);
  for (const Waypoint& p : o) {
    const V2 d = p.position_m.head<2>() - V2(10, -5);
    EXPECT_NEAR(d.norm(), 15.0, 1e-9);
    // yaw points at the centre
    EXPECT_NEAR(std::cos(p.yaw_rad) * d.x() + std::sin(p.yaw_rad) * d.y(), -15.0, 1e-9);
  }
  // From angle 0 with a lead of 0.5 rad, the next waypoint is at 2 pi / 8 (counter-clockwise).
  EXPECT_EQ(NextOrbitWaypoint(o, V2(10, -5), V2(25, -5), 0.5), 1u);
  EXPECT_EQ(NextOrbitWaypoint(o, V2(10, -5), V2(10, 10), 0.5), 3u);  // at pi/2 -> 3 pi/4
}

// Sectors on a near-square grid for any N: the cells tile the area (no gap, no overlap: the areas
// add up and no two overlap), bands across the shorter side, and fewer than 4 sectors per unit of
// aspect ratio stay strips (the shipped 3-scout trials keep theirs).
TEST(SearchPattern, PartitionTilesTheAreaWithNearSquareCellsForAnyN) {
  const Rect square{-292, -292, 292, 292};
  EXPECT_EQ(PartitionGridFor(square, 3).cells, (std::vector<std::size_t>{3}));
  EXPECT_EQ(PartitionGridFor(square, 100).cells, std::vector<std::size_t>(10, 10));
  EXPECT_EQ(PartitionGridFor(square, 40).cells, (std::vector<std::size_t>{7, 7, 7, 7, 6, 6}));
  EXPECT_EQ(PartitionGridFor(Rect{0, 0, 100, 400}, 8).cells, (std::vector<std::size_t>{8}));  // 100 x 50 m
  EXPECT_EQ(PartitionGridFor(Rect{0, 0, 100, 400}, 16).cells, (std::vector<std::size_t>{8, 8}));  // 50 x 50 m
  EXPECT_FALSE(PartitionGridFor(Rect{0, 0, 100, 400}, 8).bands_along_y);  // taller than wide
  for (const Rect& area : {square, Rect{-100, -60, 100, 60}, Rect{0, 0, 100, 400}}) {
    for (std::size_t n = 1; n <= 120; ++n) {
      std::vector<std::string> names;
      for (std::size_t i = 0; i < n; ++i) names.push_back("d" + std::to_string(i));
      const std::vector<raft::Sector> s = PartitionArea(area, names);
      ASSERT_EQ(s.size(), n);
      double total = 0;
      double worst_aspect = 0;
      for (std::size_t i = 0; i < n; ++i) {
        EXPECT_EQ(s[i].drone, names[i]);
        const Rect r = AsRect(s[i]);
        ASSERT_GT(r.width_m(), 0);
        ASSERT_GT(r.height_m(), 0);
        EXPECT_TRUE(area.Contains({r.x_min_m, r.y_min_m}) && area.Contains({r.x_max_m, r.y_max_m}));
        total += r.width_m() * r.height_m();
        worst_aspect =
            std::max(worst_aspect, std::max(r.width_m(), r.height_m()) / std::min(r.width_m(), r.height_m()));
        for (std::size_t j = 0; j < i; ++j) {
          const Rect q = AsRect(s[j]);
          const double ox = std::min(r.x_max_m, q.x_max_m) - std::max(r.x_min_m, q.x_min_m);
          const double oy = std::min(r.y_max_m, q.y_max_m) - std::max(r.y_min_m, q.y_min_m);
          EXPECT_FALSE(ox > 1e-6 && oy > 1e-6) << "cells " << i << " and " << j << " overlap";
        }
      }
      EXPECT_NEAR(total, area.width_m() * area.height_m(), 1e-6) << n;
      if (n >= 4) {
        EXPECT_LT(worst_aspect, 4.5) << n << " sectors";  // near square once there are bands
      }
    }
  }
}

// The order that hands each drone the cell matching its place: scouts on a shuffled 10 x 10 grid
// get the cells of their own column and row, whatever order their names come in.
TEST(SearchPattern, PartitionOrderMatchesCellsToWhereTheDronesAre) {
  const Rect area{-292, -292, 292, 292};
  std::vector<std::string> names;
  std::vector<V2> where;
  for (int k = 0; k < 100; ++k) {
    const int i = (k * 37) % 100;  // a permutation of 0..99
    names.push_back("scout_" + std::to_string(i + 1));
    where.push_back(V2(4.0 * (i % 10), 4.0 * (i / 10)));
  }
  std::vector<std::string> ordered;
  for (const std::size_t k : PartitionOrder(area, names, where)) ordered.push_back(names[k]);
  const std::vector<raft::Sector> s = PartitionArea(area, ordered);
  for (const raft::Sector& c : s) {
    const int i = std::stoi(c.drone.substr(6)) - 1;
    EXPECT_EQ(static_cast<int>(std::floor((c.x_min_m + 292 + 1e-6) / 58.4)), i % 10) << c.drone;
    EXPECT_EQ(static_cast<int>(std::floor((c.y_min_m + 292 + 1e-6) / 58.4)), i / 10) << c.drone;
  }
}

}  // namespace
}  // namespace swarmbox::swarm
