// Test utilities: fully populated values of every bus message, so that a field a converter forgets
// (left at its default) makes a round-trip comparison fail. Every field gets a distinct non-default
// value derived from `seed`; sequences get several elements; strings are longer than the small-
// string buffer so heap-backed strings are exercised too.
#pragma once

#include <cstddef>
#include <cstdint>

#include "swarmbox/bus/messages.hpp"

namespace swarmbox::bus::testing {

ClockTick FullClockTick(std::uint64_t seed);
SensorSample FullSensorSample(std::uint64_t seed);
ActuatorCommand FullActuatorCommand(std::uint64_t seed);
CameraImage FullCameraImage(std::uint64_t seed, std::uint32_t width_px = 32,
                            std::uint32_t height_px = 24);
WorldCommand FullWorldCommand(std::uint64_t seed);
DroneState FullDroneState(std::uint64_t seed);
RaftMessage FullRaftMessage(std::uint64_t seed, std::size_t payload_bytes = 48);
Detection FullDetection(std::uint64_t seed);
RadioPing FullRadioPing(std::uint64_t seed);
BrainMessage FullBrainMessage(std::uint64_t seed);
// `which`: 0 state, 1 detection (broadcast), 2 raft, 3 ping, 4 brain.
RadioFrame FullRadioFrame(std::uint64_t seed, int which);
Event FullEvent(std::uint64_t seed);
BrainInput FullBrainInput(std::uint64_t seed);
BrainOutput FullBrainOutput(std::uint64_t seed);
Telemetry FullTelemetry(std::uint64_t seed);
DepthSummary FullDepthSummary(std::uint64_t seed);

// Overload set for generic tests: Full<T>(seed).
template <typename T>
T Full(std::uint64_t seed);
template <> ClockTick Full<ClockTick>(std::uint64_t seed);
template <> SensorSample Full<SensorSample>(std::uint64_t seed);
template <> ActuatorCommand Full<ActuatorCommand>(std::uint64_t seed);
template <> CameraImage Full<CameraImage>(std::uint64_t seed);
template <> WorldCommand Full<WorldCommand>(std::uint64_t seed);
template <> DroneState Full<DroneState>(std::uint64_t seed);
template <> RaftMessage Full<RaftMessage>(std::uint64_t seed);
template <> Detection Full<Detection>(std::uint64_t seed);
template <> RadioPing Full<RadioPing>(std::uint64_t seed);
template <> BrainMessage Full<BrainMessage>(std::uint64_t seed);
template <> Event Full<Event>(std::uint64_t seed);
template <> BrainInput Full<BrainInput>(std::uint64_t seed);
template <> BrainOutput Full<BrainOutput>(std::uint64_t seed);
template <> Telemetry Full<Telemetry>(std::uint64_t seed);
template <> DepthSummary Full<DepthSummary>(std::uint64_t seed);

}  // namespace swarmbox::bus::testing
