// SarSwarm: the SAR mission on loopback without Docker, for integration tests: swarmbox-physics
// and one swarmbox-agent --mission sar per drone as child processes over Cyclone DDS, their logs
// in a folder, with helpers to read their event lines. Used by agent_sar_mission_test (issue #7)
// and lifter_flat_spot_test (issue #23). Needs SWARMBOX_AGENT_BIN, SWARMBOX_PHYSICS_BIN and
// SWARMBOX_TRIALS_DIR defined by the test target.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/logged_child.hpp"
#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::agent::testing {

using namespace std::chrono_literals;
using Child = swarmbox::testing::LoggedChild;

struct Line {
  double t_s = 0;
  LogfmtFields fields;
};

// Every logfmt line of `log` with event=`event` (optionally node=`node`), in order.
inline std::vector<Line> Events(const std::string& log, const std::string& event, const std::string& node = "") {
  std::vector<Line> out;
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    LogfmtFields f = ParseLogfmt(line);
    if (FindField(f, "event") != event) continue;
    if (!node.empty() && FindField(f, "node") != node) continue;
    const auto t = FindField(f, "t");
    if (!t) continue;
    out.push_back({std::stod(*t), std::move(f)});
  }
  return out;
}

inline double Field(const Line& l, const char* key) {
  const auto v = FindField(l.fields, key);
  return v ? std::stod(*v) : std::nan("");
}

struct Drone {
  const char* name;
  const char* airframe;
  const char* start;
  const char* payload;
};

// swarmbox-physics (`world`, by default the open field; rtf 0, seed 42) and one swarmbox-agent
// --mission sar per drone, on DDS domains `domain` (sim) and `domain` + 1 (mesh); with `channel`,
// the physics server hosts the simulated radio channel (wifi_5ghz_mesh) and there is no mesh domain.
class SarSwarm {
 public:
  SarSwarm(std::vector<Drone> drones, int domain, const std::string& dir, bool channel = false,
           const std::string& world = SWARMBOX_TRIALS_DIR "/worlds/open_field.yaml")
      : drones_(std::move(drones)), dir_(dir) {
    std::vector<std::string> phys = {SWARMBOX_PHYSICS_BIN, "--world", world, "--rtf", "0", "--domain",
                                     std::to_string(domain), "--max-sim-time", "600", "--seed", "42",
                                     "--truth", dir + "/truth.csv"};
    if (channel) {
      // As the runner plans a channel trial (runner::kChannelStepTimeoutS): the lost-drone rule is a
      // liveness net, not a judge of an agent the suite's load stalled for a second.
      for (const char* a : {"--radio-model", "channel", "--radio-profile", SWARMBOX_TRIALS_DIR "/radios/wifi_5ghz_mesh.yaml",
                            "--step-timeout", "30"}) {
        phys.push_back(a);
      }
    }
    std::string members;
    for (const Drone& dr : drones_) {
      phys.push_back("--drone");
      std::string spec = std::string(dr.name) + ":" + dr.airframe + ":" + dr.start;
      if (*dr.payload != '\0') spec += std::string(":0:") + dr.payload + ":ground";
      phys.push_back(spec);
      members += (members.empty() ? "" : ",") + std::string(dr.name);
    }
    wall_start_ = std::chrono::steady_clock::now();
    physics_ = std::make_unique<Child>(phys, dir + "/physics.log");
    for (const Drone& dr : drones_) {
      std::vector<std::string> argv = {SWARMBOX_AGENT_BIN, "--name", dr.name, "--airframe",
                                       std::string(SWARMBOX_TRIALS_DIR "/airframes/") + dr.airframe + ".yaml",
                                       "--sim-domain", std::to_string(domain), "--mesh-domain",
                                       std::to_string(domain + 1), "--start", dr.start, "--members", members,
                                       "--seed", "42", "--raft-dir", dir + "/raft_" + dr.name, "--mission", "sar",
                                       "--world", world, "--inference-latency-ms", "40", "--sample-timeout", "60",
                                       "--stall-timeout", "20"};
      if (*dr.payload != '\0') {
        argv.push_back("--payload");
        argv.push_back(dr.payload);
      }
      if (channel) {
        argv.push_back("--radio-model");
        argv.push_back("channel");
      }
      agents_.push_back(std::make_unique<Child>(argv, dir + "/" + dr.name + ".log"));
    }
  }

  bool started() const {
    bool ok = physics_->pid() > 0;
    for (const auto& a : agents_) ok = ok && a->pid() > 0;
    return ok;
  }

  // Polls every `poll` (wall) until some agent logs mission_complete, or an agent not killed
  // here or the physics server has exited, or `wall_limit`, or `done` (if given) returns true;
  // `each_poll` runs at every poll (it may Kill() an agent). Then stops every process. The
  // earliest mission_complete, if any.
  std::optional<Line> Run(std::chrono::milliseconds poll, std::chrono::seconds wall_limit,
                          const std::function<void()>& each_poll, const std::function<bool()>& done = {}) {
    std::optional<Line> complete;
    const auto deadline = wall_start_ + wall_limit;
    while (std::chrono::steady_clock::now() < deadline && physics_->Wait(0ms) == -1) {
      for (auto& a : agents_) {
        const auto c = Events(a->ReadLog(), "mission_complete");
        if (!c.empty() && (!complete || c.front().t_s < complete->t_s)) complete = c.front();
      }
      if (complete) break;
      bool all_running = true;  // an agent that died (bad config, crash) ends the wait
      for (std::size_t i = 0; i < agents_.size(); ++i) {
        all_running = all_running && (i == killed_ || agents_[i]->Wait(0ms) == -1);
      }
      if (!all_running) break;
      if (done && done()) break;
      if (each_poll) each_poll();
      std::this_thread::sleep_for(poll);
    }
    wall_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
    for (std::size_t i = 0; i < agents_.size(); ++i) {
      if (i != killed_) agents_[i]->Terminate();
    }
    physics_->Terminate();
    for (std::size_t i = 0; i < agents_.size(); ++i) {
      if (i != killed_) {
        EXPECT_EQ(agents_[i]->Wait(30s), 0) << drones_[i].name;
      }
    }
    physics_->Wait(30s);
    return complete;
  }

  // SIGKILL to agent `i` (at most one per run).
  void Kill(std::size_t i) {
    killed_ = i;
    agents_[i]->Signal(SIGKILL);
    EXPECT_EQ(agents_[i]->Wait(10s), 128 + SIGKILL) << drones_[i].name;
  }

  std::size_t size() const { return agents_.size(); }
  const Drone& drone(std::size_t i) const { return drones_[i]; }
  std::string Log(std::size_t i) const { return agents_[i]->ReadLog(); }
  std::string PhysicsLog() const { return physics_->ReadLog(); }
  std::string AllLogs() const {
    std::string s = "---- physics\n" + physics_->ReadLog();
    for (std::size_t i = 0; i < agents_.size(); ++i) s += std::string("---- ") + drones_[i].name + "\n" + agents_[i]->ReadLog();
    return s;
  }
  double wall_s() const { return wall_s_; }
  const std::string& dir() const { return dir_; }

 private:
  std::vector<Drone> drones_;
  std::string dir_;
  std::unique_ptr<Child> physics_;
  std::vector<std::unique_ptr<Child>> agents_;
  std::chrono::steady_clock::time_point wall_start_;
  std::size_t killed_ = static_cast<std::size_t>(-1);
  double wall_s_ = 0;
};

}  // namespace swarmbox::agent::testing
