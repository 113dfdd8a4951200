#include "frame_wait.hpp"

#include "wait_budget.hpp"

namespace swarmbox::agent {

FrameWait TakeStepFrames(bus::Subscriber<bus::CameraImage>& sub, std::int64_t sim_time_ns, bool due,
                         std::chrono::milliseconds timeout, const volatile std::sig_atomic_t* stop,
                         FrameBuffers* frames) {
  frames->count = 0;
  bool have_step = false;
  auto take = [&](bool wait, std::chrono::milliseconds slice) {
    if (frames->count == frames->images.size()) frames->images.emplace_back();
    bus::CameraImage& img = frames->images[frames->count];
    const bool took = wait ? sub.TakeFor(img, slice) : sub.Take(img);
    if (!took) return false;
    ++frames->count;
    // The step's own frame is its colour (or stereo) frame: a thermal frame goes out just before
    // the colour frame it was taken with, so once that is here the thermal one is too.
    have_step = have_step || (img.sim_time_ns == sim_time_ns && img.encoding != bus::kThermalEncoding);
    return true;
  };
  while (take(false, {})) {
  }
  if (!due || have_step) return FrameWait::kTaken;
  WaitBudget budget(timeout);
  while (!have_step) {
    if (stop != nullptr && *stop != 0) return FrameWait::kStopped;
    if (budget.spent()) {
      // Past the liveness bound: look once more, then go on without it.
      while (!have_step && take(false, {})) {
      }
      return have_step ? FrameWait::kTaken : FrameWait::kMissing;
    }
    const auto slice = budget.Slice(std::chrono::milliseconds(50));
    const auto start = std::chrono::steady_clock::now();
    (void)take(true, slice);
    budget.Spend(std::chrono::steady_clock::now() - start, slice);
  }
  return FrameWait::kTaken;
}

}  // namespace swarmbox::agent
