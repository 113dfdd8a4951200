// Ctrl-C (SIGINT) and SIGTERM during `swarmbox run` and `swarmbox experiment`: the first one asks
// the runner to tear the trial down cleanly (the flag below); the handler then restores the
// default action, so a second one kills swarmbox at once (`swarmbox gc` removes what that leaves).
// After the clean-up the command exits 128 + the signal's number, as a shell reports a process
// the signal ended: 130 for SIGINT, 143 for SIGTERM (InterruptExitCode).
#pragma once

#include <atomic>

namespace swarmbox::cli {

// Installs the handlers; returns the flag they set. Call once.
const std::atomic<bool>& InstallInterruptHandlers();

// The first signal the handlers caught (SIGINT or SIGTERM), 0 while none.
int InterruptSignal();

// 128 + InterruptSignal(): 130 after Ctrl-C, 143 after SIGTERM (kExitOutcome if none was caught,
// which does not happen when the flag is set).
int InterruptExitCode();

// "interrupted (Ctrl-C)" or "interrupted (SIGTERM)", for messages.
const char* InterruptName();

}  // namespace swarmbox::cli
