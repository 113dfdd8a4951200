// A SAR trial's recorded channels, made up but shaped as the recorder writes them (ARCHITECTURE.md
// "Recordings"): the open field (200 m x 200 m, two victims, a few obstacles), three scouts
// sweeping their sectors and a lifter flying to a victim, a Raft failover (scout_1 leads term 1,
// scout_2 term 2 from t=62 s), measured links whose loss grows with distance, detections, 1 Hz
// JPEG camera frames (OpenCV) and log events. Deterministic: the same calls give the same bytes.
//
// For the page's tests (live_view_test.cpp): the positions it returns are where each drone is at
// a time, so a test can check what the page draws.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "swarmbox/record/sink.hpp"

namespace swarmbox::testing {

inline const std::vector<std::string> kScenarioDrones = {"lifter", "scout_1", "scout_2", "scout_3"};
inline constexpr double kScenarioDurationS = 120.0;

// Where `drone` is at simulated time t [s]: ENU [m].
std::array<double, 3> ScenarioPosition(const std::string& drone, double t_s);

// Adds every channel to `sink` and writes the whole trial, in time order.
Status WriteSarScenario(record::Sink& sink);

}  // namespace swarmbox::testing
