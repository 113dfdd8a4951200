// Fakes for SimServer tests: a fake wall clock and a scripted transport that answers every
// published sample at once (as agents would), with what the test put in for the next answer.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "sim_server.hpp"

namespace swarmbox::physics::testing {

constexpr std::int64_t kMs = 1'000'000;

class FakeClock final : public WallClock {
 public:
  std::int64_t NowNs() override { return now_ns; }
  void SleepUntilNs(std::int64_t t) override { now_ns = std::max(now_ns, t); }
  std::int64_t now_ns = 0;
};
// Answers each published sample with a command for the same step, from the drones listed as
// alive; waiting without an answer advances the fake clock to the deadline.
class ScriptedAgents final : public SimTransport {
 public:
  explicit ScriptedAgents(FakeClock& clock) : clock_(clock) {}
  Status PublishSample(std::size_t, const std::string& name, const SensorSample& s, const SampleExtras& extras) override {
    ++samples[name];
    last_step[name] = s.step;
    published.push_back("sample " + name + " " + std::to_string(s.step) + (extras.camera_frame ? " camera_frame" : "") +
                        (extras.stereo_frame ? " stereo_frame" : ""));
    for (const bus::RadioFrame& f : extras.radio_in) heard[name].push_back({s.step, f});
    if (alive[name] && clock_.now_ns >= alive_from_ns[name]) {
      ActuatorInput in{name, s.step, !motors_off[name], std::vector<double>(4, throttle), leader[name], {}, {}};
      in.world = std::exchange(answer_world[name], {});
      in.radio_out = std::exchange(answer_radio[name], {});
      pending_.push_back(std::move(in));
    }
    return Ok{};
  }
  Status PublishCamera(std::size_t, const std::string& name, std::uint64_t step, const CameraImage& img) override {
    ++frames[name];
    published.push_back("camera " + name + " " + std::to_string(step));
    // A shipped airframe's camera (trials/airframes): x500 640 x 360, x8_heavy 320 x 240.
    const bool shipped = (img.width_px == 640 && img.height_px == 360) || (img.width_px == 320 && img.height_px == 240);
    EXPECT_TRUE(shipped) << name << ": " << img.width_px << " x " << img.height_px;
    EXPECT_EQ(img.bgr.size(), static_cast<std::size_t>(img.width_px) * static_cast<std::size_t>(img.height_px) * 3u);
    return Ok{};
  }
  Status PublishThermal(std::size_t, const std::string& name, std::uint64_t step,
                        const ThermalImage& img) override {
    published.push_back("thermal " + name + " " + std::to_string(step));
    EXPECT_EQ(img.centikelvin.size(),
              static_cast<std::size_t>(img.width_px) * static_cast<std::size_t>(img.height_px));
    return Ok{};
  }
  Status PublishStereo(std::size_t, const bus::CameraImage& pair) override {
    published.push_back("stereo " + pair.drone + " " + std::to_string(pair.step));
    pairs[pair.drone].push_back(pair);
    return Ok{};
  }
  Status PublishClock(std::uint64_t step, std::int64_t, std::int64_t, double) override {
    last_clock_step = step;
    return Ok{};
  }
  Status PublishStatus(const JoiningStatus& status, bool done) override {
    statuses.push_back({clock_.now_ns, status, done});
    return Ok{};
  }
  void WaitActuators(std::int64_t deadline_ns, std::size_t /*awaited*/, std::vector<ActuatorInput>* out) override {
    if (pending_.empty()) {
      clock_.now_ns = std::max(clock_.now_ns, deadline_ns);
      return;
    }
    clock_.now_ns += 1 * kMs;  // agents answer within a millisecond
    out->insert(out->end(), pending_.begin(), pending_.end());
    pending_.clear();
  }
  void TakeWorldCommands(std::vector<WorldCommandInput>* out) override {
    out->insert(out->end(), world_commands.begin(), world_commands.end());
    world_commands.clear();
  }

  std::map<std::string, bool> alive;
  std::map<std::string, std::int64_t> alive_from_ns;                  // answers from then on
  std::map<std::string, bool> leader;                                 // raft_leader in answers
  std::map<std::string, bool> motors_off;                             // answers armed = false
  std::map<std::string, std::vector<WorldCommandInput>> answer_world;  // in the next answer
  std::map<std::string, std::vector<bus::RadioFrame>> answer_radio;    // in the next answer
  struct Heard {
    std::uint64_t step;   // of the sample that carried it
    bus::RadioFrame frame;
  };
  std::map<std::string, std::vector<Heard>> heard;                     // radio_in, in order
  std::map<std::string, int> samples, frames;
  std::map<std::string, std::uint64_t> last_step;
  std::vector<std::string> published;  // "camera a 25", "stereo a 25", "sample a 25 camera_frame", in order
  std::map<std::string, std::vector<bus::CameraImage>> pairs;          // stereo pairs, in order
  struct StatusSent {
    std::int64_t wall_ns;  // the fake clock's time
    JoiningStatus status;
    bool done;
  };
  std::vector<StatusSent> statuses;    // PublishStatus, in order
  std::vector<WorldCommandInput> world_commands;
  double throttle = 0;
  std::uint64_t last_clock_step = 0;

 private:
  FakeClock& clock_;
  std::vector<ActuatorInput> pending_;
};

inline std::string ReadFile(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, f)) s.append(buf, n);
  return s;
}

}  // namespace swarmbox::physics::testing
