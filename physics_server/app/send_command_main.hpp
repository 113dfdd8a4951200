// The `--send-command` mode of swarmbox-physics (send_command_main.cpp): main() hands the whole
// command line over when it sees that flag.
#pragma once

#include <optional>

namespace CLI {
class App;
}  // namespace CLI

namespace swarmbox::physics {

// Both modes' command-line parse: nothing when the flags are good, else the exit code (0 after
// --help or --version, 2 for a usage error, CLI11's message printed).
std::optional<int> ParseOrExitCode(CLI::App& app, int argc, char** argv);

// Whether argv asks for the one-shot sender.
bool IsSendCommand(int argc, char** argv);
// `--send-command <target> <command> [args...] [--sim-interface I] [--domain D] [--middleware M]
// [--match-timeout S]`; returns the exit code (0 sent, 2 bad input, 3 no server / bus failure).
int RunSendCommand(int argc, char** argv);

}  // namespace swarmbox::physics
