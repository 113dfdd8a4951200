// LogFollower: follows one container's log stream on its own thread. Each line is appended to the
// component's log file (<trial dir>/logs/<component>.log) and pushed to the LogHub as a kLine item
// tagged with the follower's generation; when the stream ends (by itself, broken, or cancelled) a
// kStreamEnd item follows (its text: why it broke, "" when it ended by itself or was cancelled).
// Wall times of items are Clock seconds since `start_wall_s`.
//
// LogFollowers: the current follower of each component, and the generations that tell a current
// follower's items from those of one replaced after a restart (ResumeLogs in DockerEngine).
//
//   LogFollowers followers(api, hub, clock, {trial_dir + "/logs", start_wall_s});
//   followers.Start("scout_1", container_id);                  // after the container started
//   ... hub items: followers.IsCurrent(item)
//   std::uint64_t lines = followers.Finish("scout_1", kStreamEndGrace);  // the stream's end, joined
//
// Thread-safety: every method of both classes may be called from any thread. A LogFollower calls
// `on_end` (from its own thread) once its stream has ended; DockerEngine uses it to wake a stop
// waiting for the container's program to exit.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/runner/clock.hpp"
#include "swarmbox/runner/log_hub.hpp"

namespace swarmbox::runner {

class LogFollower {
 public:
  struct Options {
    std::string component;
    std::string container_id;
    std::string log_path;          // appended to ("cannot write <path>" ends the stream if it cannot)
    double start_wall_s = 0;       // Clock time the trial started
    std::uint64_t generation = 0;  // tags every item
    // Lines an earlier follower delivered already (Docker keeps a restarted container's earlier
    // runs' lines): skipped, neither written nor pushed.
    std::uint64_t skip_lines = 0;
    std::function<void()> on_end;  // may be empty
  };

  // Starts following at once.
  LogFollower(docker::DockerApi& api, LogHub& hub, Clock& clock, Options options);
  ~LogFollower();  // Finish(0): cancels and joins
  LogFollower(const LogFollower&) = delete;
  LogFollower& operator=(const LogFollower&) = delete;

  // The stream ended (by itself, broken or cancelled).
  bool ended() const { return ended_.load(); }
  // The stream ended by itself: the container's output closed (its program exited).
  bool ended_by_itself() const { return ended_.load() && clean_end_.load(); }
  std::uint64_t generation() const { return options_.generation; }
  // Waits up to `grace` for the stream to end by itself, then cancels it and joins the thread;
  // returns the lines it delivered. Idempotent.
  std::uint64_t Finish(std::chrono::milliseconds grace);
  // Asks the stream to end without waiting (Finish joins).
  void Cancel() { cancel_.Cancel(); }

 private:
  void Follow(docker::DockerApi& api, LogHub& hub, Clock& clock);

  const Options options_;
  docker::CancelToken cancel_;
  std::atomic<bool> ended_{false};
  std::atomic<bool> clean_end_{false};
  std::atomic<std::uint64_t> lines_{0};
  std::mutex end_mu_;  // ended_ is set and waited for under it
  std::condition_variable end_cv_;
  std::mutex join_mu_;  // one Finish joins
  std::thread thread_;
};

class LogFollowers {
 public:
  struct Options {
    std::string logs_dir;     // <trial dir>/logs; must exist
    double start_wall_s = 0;  // Clock time the trial started
    std::function<void()> on_end;  // given to every follower
  };

  LogFollowers(docker::DockerApi& api, LogHub& hub, Clock& clock, Options options);
  ~LogFollowers();  // cancels and joins every follower still running

  // Replaces the component's follower (cancelling the previous one, whose items stop being
  // current) with a new one from the stream's `skip_lines`-th line. Returns the lines the
  // previous follower had delivered (0 without one).
  std::uint64_t Start(const std::string& component, const std::string& container_id,
                      std::uint64_t skip_lines = 0);
  // Ends the component's follower (LogFollower::Finish with `grace`) and forgets it; its items
  // stay current until another is started. Returns its lines (0 without one).
  std::uint64_t Finish(const std::string& component, std::chrono::milliseconds grace);
  // Whether a hub item comes from the component's current (or last finished) follower.
  bool IsCurrent(const HubItem& item) const;
  // The component's follower's stream ended by itself.
  bool EndedByItself(const std::string& component) const;

 private:
  std::unique_ptr<LogFollower> Take(const std::string& component);

  docker::DockerApi& api_;
  LogHub& hub_;
  Clock& clock_;
  const Options options_;
  mutable std::mutex mu_;
  std::map<std::string, std::unique_ptr<LogFollower>> followers_;  // guarded by mu_
  std::map<std::string, std::uint64_t> generations_;  // component -> current; guarded by mu_
  std::uint64_t next_generation_ = 1;                 // guarded by mu_
};

}  // namespace swarmbox::runner
