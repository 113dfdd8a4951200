// Process plumbing of swarmbox-netemd: forking into the background with a readiness handshake,
// pidfiles, stopping a daemon by its pidfile, and a minimal pid 1 for the fault sidecar.
#pragma once

#include <functional>
#include <string>

#include "swarmbox/common/result.hpp"

namespace swarmbox::faults {

// Forks. The child calls `ready_work` (which must call the given `ready()` once it can serve, or
// return an error before that) and then runs to the end; the parent returns 0 once the child is
// ready, or prints the child's error and returns 1. Returns -1 in the child after its work ends
// (so main returns the child's own code through `child_exit`).
int Daemonize(const std::string& pidfile, const std::function<int(const std::function<void()>& ready)>& ready_work);

// Sends SIGTERM to the swarmbox-netemd named in `pidfile` and waits up to timeout_ms for it to go.
// Refuses a pid that is not a swarmbox-netemd. Removes the pidfile.
Status StopByPidfile(const std::string& pidfile, int timeout_ms);

// Sleeps as pid 1 of a container: reaps children, exits 0 on SIGTERM or SIGINT.
int SleepAsInit();

}  // namespace swarmbox::faults
