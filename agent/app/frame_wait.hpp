// TakeStepFrames: a lockstep image topic's frames for one step (the RGB camera's, the stereo
// pair's). The physics server publishes a step's frame before its sample, but DDS may hand the
// sample over first (two readers); a sample that says a frame belongs to its step (camera_frame,
// stereo_frame) makes the agent wait for it: what a camera saw at t_k is part of step k. The wait
// is a wall-clock liveness bound only (WaitBudget): the frame decides nothing by its arrival time.
//
//   FrameBuffers frames;
//   switch (TakeStepFrames(*sub, msg.sim_time_ns, msg.camera_frame, timeout, stop, &frames)) { ... }
//   for (std::size_t i = 0; i < frames.count; ++i) Use(frames.images[i]);
#pragma once

#include <chrono>
#include <csignal>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "swarmbox/bus/messages.hpp"
#include "swarmbox/bus/participant.hpp"

namespace swarmbox::agent {

// The frames taken for one step; the buffers are reused from step to step (no allocation once
// they have grown to a step's frames).
struct FrameBuffers {
  std::vector<bus::CameraImage> images;
  std::size_t count = 0;
};

enum class FrameWait {
  kTaken,    // every waiting frame taken; the step's own among them, or none was due
  kMissing,  // due, but not there within the timeout (the caller logs it and goes on)
  kStopped,  // *stop was set while waiting
};

// Takes every frame waiting on `sub` into `frames` (count reset first) and, when `due` and the
// frame of `sim_time_ns` is not among them, waits up to `timeout` for it in 50 ms slices. A
// thermal frame (bus::kThermalEncoding) is taken but is not the step's frame: it precedes it.
FrameWait TakeStepFrames(bus::Subscriber<bus::CameraImage>& sub, std::int64_t sim_time_ns, bool due,
                         std::chrono::milliseconds timeout, const volatile std::sig_atomic_t* stop,
                         FrameBuffers* frames);

}  // namespace swarmbox::agent
