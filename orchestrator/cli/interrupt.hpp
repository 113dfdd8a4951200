// Ctrl-C (SIGINT) and SIGTERM during `swarmbox run`: the first one asks the runner to tear the
// trial down cleanly (the flag below); the handler then restores the default action, so a second
// Ctrl-C kills swarmbox at once (`swarmbox gc` removes what that leaves).
#pragma once

#include <atomic>

namespace swarmbox::cli {

// Installs the handlers; returns the flag they set. Call once.
const std::atomic<bool>& InstallInterruptHandlers();

}  // namespace swarmbox::cli
