// The lifter's drop-spot check with stereo depth (issue #23), end to end on loopback: the SAR
// mission of trials/lifter_flat_spot.yaml (three x500 scouts, the lifter with the stretcher) in
// worlds/rubble_drop.yaml (gravel), whose one victim lies beside a rubble field covering the lifter's usual
// drop point, flown as far as the stretcher coming to rest beside the victim (the physics server's
// event=payload_at_rest after the first release). Twice, the lifter's airframe the only
// difference:
//   x8_heavy        no depth camera: the stretcher is set down blind on the rubble (raised or
//                   tilted, or both);
//   x8_heavy_depth  the OAK-D Pro (stereo pair rendered by the physics server, SGBM on the
//                   agent): the lifter surveys from its transit altitude, chooses a flat spot off
//                   the rubble (event=drop_spot_chosen) and the stretcher rests flat on the ground.
// On the simulated radio channel (radio.model channel), as a trial runs by default: the lockstep
// then makes every run the same (the netem model's real DDS on the wall clock changed which
// sightings reached the leader before a confirmation, and so the drop point, run to run).
// Prints where and how each came to rest, and the survey's figures. DDS domains 80-87.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "sar_swarm.hpp"
#include "support/files.hpp"

namespace swarmbox::agent::testing {
namespace {

using swarmbox::testing::MakeTempDir;

// The world's victim and heaps (trials/worlds/rubble_drop.yaml): centres of 1.5 x 1.5 m blocks.
constexpr double kVictimX = 35.0, kVictimY = 20.0;
constexpr double kHeapHalf = 0.75;
constexpr std::array<std::array<double, 2>, 8> kHeaps = {{{31.02, 16.35}, {31.02, 18.05}, {31.02, 19.75},
                                                          {32.72, 16.35}, {32.72, 18.05}, {32.72, 19.75},
                                                          {34.42, 16.35}, {34.42, 18.05}}};
// The stretcher (x8_heavy.yaml payload): 2.0 x 0.6 x 0.25 m; lying flat its centre is 0.125 m up.
constexpr double kStretcherHalfHeight = 0.125;
// Flat on flat ground: within 3 deg and 5 cm of lying on the ground. On rubble: raised by at
// least 0.25 m or tilted by more than 5 deg (the heaps are 0.5-0.8 m high).
constexpr double kFlatTiltDeg = 3.0;
constexpr double kFlatRaiseM = 0.05;
constexpr double kRubbleRaiseM = 0.25;
constexpr double kRubbleTiltDeg = 5.0;

struct Rest {
  bool seen = false;
  double t_s = 0, x_m = 0, y_m = 0, z_m = 0, tilt_deg = 0;
};

// The first event=payload_at_rest of the lifter in the physics log: the stretcher set down beside
// the victim (it starts lying at home, and rests again only after a release).
Rest FirstRest(const std::string& physics_log) {
  const auto rests = Events(physics_log, "payload_at_rest");
  if (rests.empty()) return {};
  const Line& r = rests.front();
  return {true, r.t_s, Field(r, "x"), Field(r, "y"), Field(r, "z"), Field(r, "tilt_deg")};
}

// How far the point (x, y) is outside every heap's footprint (negative: inside one).
double ClearanceFromHeaps(double x, double y) {
  double best = 1e9;
  for (const auto& h : kHeaps) {
    const double dx = std::abs(x - h[0]) - kHeapHalf;
    const double dy = std::abs(y - h[1]) - kHeapHalf;
    const double outside = std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
    best = std::min(best, outside > 0 ? outside : std::max(dx, dy));
  }
  return best;
}

struct Flight {
  Rest rest;
  std::string lifter_log;
  std::string logs;
  std::string dir;
  double wall_s = 0;
};

// The mission with the lifter on `lifter_airframe`, until the stretcher rests beside the victim
// (or the mission ends, a process dies, or 840 s of wall time pass).
Flight FlyToTheDrop(const char* lifter_airframe, int domain) {
  Flight f;
  f.dir = MakeTempDir("swarmbox_flat_spot_");
  const std::vector<Drone> drones = {{"scout_1", "x500", "0,0,0", ""},
                                     {"scout_2", "x500", "3,0,0", ""},
                                     {"scout_3", "x500", "6,0,0", ""},
                                     {"lifter", lifter_airframe, "0,-10,0", "stretcher"}};
  SarSwarm swarm(drones, domain, f.dir, /*channel=*/true, SWARMBOX_TRIALS_DIR "/worlds/rubble_drop.yaml");
  EXPECT_TRUE(swarm.started());
  (void)swarm.Run(1s, 840s, nullptr, [&] { return FirstRest(swarm.PhysicsLog()).seen; });
  f.rest = FirstRest(swarm.PhysicsLog());
  f.lifter_log = swarm.Log(3);
  f.logs = swarm.AllLogs();
  f.wall_s = swarm.wall_s();
  return f;
}

void Print(const char* label, const Flight& f) {
  std::printf("%s rest_t_s=%.1f x=%.2f y=%.2f z=%.3f tilt_deg=%.1f heap_clearance_m=%.2f wall_s=%.0f\n", label,
              f.rest.t_s, f.rest.x_m, f.rest.y_m, f.rest.z_m, f.rest.tilt_deg,
              ClearanceFromHeaps(f.rest.x_m, f.rest.y_m), f.wall_s);
  std::fflush(stdout);
}

TEST(LifterFlatSpot, WithoutDepthTheStretcherIsSetDownOnTheRubble) {
  const Flight f = FlyToTheDrop("x8_heavy", 80 + static_cast<int>(getpid() % 2) * 2);
  ASSERT_TRUE(f.rest.seen) << "no event=payload_at_rest after " << f.wall_s << " s wall:\n" << f.logs;
  Print("no_depth", f);
  EXPECT_LT(std::hypot(f.rest.x_m - kVictimX, f.rest.y_m - kVictimY), 8.0) << "set down away from the victim";
  EXPECT_TRUE(Events(f.lifter_log, "drop_spot_survey").empty()) << "no depth camera, no survey";
  const bool raised = f.rest.z_m - kStretcherHalfHeight > kRubbleRaiseM;
  EXPECT_TRUE(raised || f.rest.tilt_deg > kRubbleTiltDeg)
      << "the blind drop was meant to land on the rubble: z=" << f.rest.z_m << " tilt=" << f.rest.tilt_deg;
  if (::testing::Test::HasFailure()) std::fprintf(stderr, "logs in %s\n", f.dir.c_str());
}

TEST(LifterFlatSpot, WithDepthTheLifterChoosesAFlatSpotOffTheRubble) {
  const Flight f = FlyToTheDrop("x8_heavy_depth", 84 + static_cast<int>(getpid() % 2) * 2);
  ASSERT_TRUE(f.rest.seen) << "no event=payload_at_rest after " << f.wall_s << " s wall:\n" << f.logs;
  Print("depth", f);
  const auto surveys = Events(f.lifter_log, "drop_spot_survey");
  ASSERT_FALSE(surveys.empty()) << f.lifter_log;
  const Line& s = surveys.front();
  std::printf("depth survey candidates=%s flat=%s default_ok=%s default_slope_deg=%s default_height_m=%s fill=%s\n",
              FindField(s.fields, "candidates").value_or("?").c_str(), FindField(s.fields, "flat").value_or("?").c_str(),
              FindField(s.fields, "default_ok").value_or("?").c_str(),
              FindField(s.fields, "default_slope_deg").value_or("-").c_str(),
              FindField(s.fields, "default_height_m").value_or("-").c_str(), FindField(s.fields, "fill").value_or("?").c_str());
  // The default point is on the rubble: the survey must have seen that, and moved the drop point.
  EXPECT_EQ(FindField(s.fields, "default_ok"), "false") << f.lifter_log;
  const auto chosen = Events(f.lifter_log, "drop_spot_chosen");
  ASSERT_FALSE(chosen.empty()) << f.lifter_log;
  EXPECT_GT(Field(chosen.front(), "moved_m"), 1.0);
  // The stretcher lies flat on the ground, off every heap, beside (not on) the victim.
  EXPECT_LT(f.rest.tilt_deg, kFlatTiltDeg);
  EXPECT_LT(std::abs(f.rest.z_m - kStretcherHalfHeight), kFlatRaiseM);
  EXPECT_GT(ClearanceFromHeaps(f.rest.x_m, f.rest.y_m), 0.0);
  EXPECT_LT(std::hypot(f.rest.x_m - kVictimX, f.rest.y_m - kVictimY), 10.0);
  if (::testing::Test::HasFailure()) std::fprintf(stderr, "logs in %s\n", f.dir.c_str());
}

}  // namespace
}  // namespace swarmbox::agent::testing
