// ServerThread: a SimServer running its loop on a thread of its own, for the tests that play the
// agents on the test's thread over a real transport (bus_lockstep_test, command_sender_test).
// Its events go to `events_out` (a tmpfile the test reads back with ReadAll). The destructor asks
// the loop to stop and joins it, so a failed ASSERT in the agent loop ends the test cleanly.
//
//   std::FILE* out = std::tmpfile();
//   ServerThread server(*world, **transport, options, out);
//   while (!server.done()) { ... answer the sensor samples ... }
//   ASSERT_TRUE(server.Join().ok());
//   const std::string log = ReadAll(out);
#pragma once

#include <atomic>
#include <cstdio>
#include <string>
#include <thread>

#include "sim_server.hpp"

namespace swarmbox::physics::testing {

// Everything written to `f` so far (it is flushed and rewound first).
inline std::string ReadAll(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, f)) s.append(buf, n);
  return s;
}

class ServerThread {
 public:
  ServerThread(World& world, SimTransport& transport, const SimServerOptions& options, std::FILE* events_out)
      : server_(world, transport, clock_, nullptr, options, events_out), thread_([this] {
          result_ = server_.Run(stop_);
          done_ = true;
        }) {}
  ~ServerThread() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  ServerThread(const ServerThread&) = delete;
  ServerThread& operator=(const ServerThread&) = delete;

  // True once Run() has returned (max_sim_time_s reached, or an error).
  bool done() const { return done_.load(); }
  // Waits for Run() to return; its result.
  Status Join() {
    if (thread_.joinable()) thread_.join();
    return result_;
  }

 private:
  SteadyWallClock clock_;
  SimServer server_;
  std::atomic<bool> stop_{false}, done_{false};
  Status result_;
  std::thread thread_;  // last: starts once everything it uses exists
};

}  // namespace swarmbox::physics::testing
