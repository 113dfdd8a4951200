// StereoCapture: the stereo pairs of a trial's drones (issue #23): which drones carry the OAK-D
// Pro pair (Airframe::stereo.enabled), at which steps a pair is due, and the pair itself,
// rendered by StereoRenderer over MakeWorldScene's patch of the world around the drone and packed
// into the bus layout of a pair (bus/messages.hpp, CameraImage: left | right side by side, mono8).
//
//   StereoCapture stereo(world);              // reads the airframes; nothing to do without stereo
//   if (stereo.Due(i, step)) stereo.Capture(world, i, step, &pair);   // then publish `pair`
//
// Schedule: a pair at step k when k is a multiple of PeriodSteps(rate_hz, control period), the
// same in every run (no wall clock). The patch: PatchHalfSizeM around the drone's (x, y), rebuilt
// for every pair. The read noise: NoiseSeed(world seed, drone, step). So a pair depends on the
// world, the seed and the drone's pose only.
// Not thread-safe (one renderer, scratch buffers); the server's thread only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmbox/bus/messages.hpp"
#include "swarmbox/physics/stereo_renderer.hpp"
#include "swarmbox/physics/stereo_scene.hpp"
#include "swarmbox/physics/world.hpp"

namespace swarmbox::physics {

// The pair's patch of the world: the ground the widest view covers from `height_m` (with room
// for tilt: kPatchViewMargin times the half width, plus kPatchMargin_m), capped at
// kMaxPatchHalfSize_m (a drone high up sees no more than that: the ray caster clamps to the border).
inline constexpr double kPatchViewMargin = 1.5;
inline constexpr double kPatchMargin_m = 2.0;
inline constexpr double kMaxPatchHalfSize_m = 30.0;

// Packs a rendered pair into the bus layout (bus/messages.hpp, CameraImage's stereo paragraph).
void PackStereoPair(const StereoFrame& frame, const std::string& drone, std::uint64_t step, std::int64_t time_ns,
                    bus::CameraImage* out);

class StereoCapture {
 public:
  // Control steps between pairs at `rate_hz`: round(1 / (rate_hz * period)), at least 1.
  static std::uint64_t PeriodSteps(double rate_hz, std::int64_t control_period_ns);
  static double PatchHalfSizeM(double height_m, double hfov_rad);
  static std::uint64_t NoiseSeed(std::uint64_t world_seed, std::size_t drone, std::uint64_t step);

  explicit StereoCapture(const World& world);
  StereoCapture(const StereoCapture&) = delete;  // the renderer points at scene_
  StereoCapture& operator=(const StereoCapture&) = delete;

  bool any() const { return any_; }  // some drone has a pair
  bool Due(std::size_t drone, std::uint64_t step) const;
  // Renders drone `drone`'s pair at the world's current time (its true pose) into `out`.
  void Capture(const World& world, std::size_t drone, std::uint64_t step, bus::CameraImage* out);

 private:
  std::vector<std::uint64_t> period_steps_;  // per drone; 0: no stereo pair
  bool any_ = false;
  StereoScene scene_;
  StereoRenderer renderer_{&scene_};         // keeps &scene_, rebuilt in place for each pair
  StereoFrame frame_;
};

}  // namespace swarmbox::physics
