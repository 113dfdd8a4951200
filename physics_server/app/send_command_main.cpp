// `swarmbox-physics --send-command <target> <command> [args...]`: one world command to a running
// physics server over the sim bus (command_sender.hpp), then exit. `-` as the target is the whole
// world (wind_gust). Exit codes: 0 sent, 2 bad input (unknown command, wrong arguments), 3 no
// server matched or the bus failed.
#include "send_command_main.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "command_sender.hpp"
#include "world_commands.hpp"

namespace swarmbox::physics {

bool IsSendCommand(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::string_view(argv[i]) == "--send-command") return true;
  }
  return false;
}

namespace {

constexpr int kExitBadInput = 2;
constexpr int kExitNotSent = 3;

struct SendArgs {
  std::vector<std::string> words;  // <target> <command> [args...]
  std::string interface = "lo";
  std::string middleware = "cyclonedds";
  int domain = 0;
  double timeout_s = 5.0;
};

// The flags into *args; the exit code of --help or a usage error.
std::optional<int> ParseSendArgs(int argc, char** argv, SendArgs* args) {
  std::string commands;
  for (const WorldCommandSpec& s : WorldCommandSpecs()) {
    commands += "\n  " + std::string(s.name) + (s.needs_drone ? " <drone>" : " -") + ": " + std::string(s.usage);
  }
  CLI::App app{"swarmbox-physics --send-command: one world command to a running physics server over the sim bus"};
  app.add_option("--send-command", args->words, "<target> <command> [args...]; target '-' = the whole world. Commands:" + commands)
      ->required()
      ->expected(-2);
  app.add_option("--sim-interface", args->interface, "Network interface of the sim bus")->capture_default_str();
  app.add_option("--domain", args->domain, "DDS domain id of the sim bus")->check(CLI::Range(0, 232))->capture_default_str();
  app.add_option("--middleware", args->middleware, "DDS implementation")->check(CLI::IsMember({"cyclonedds", "fastdds"}))->capture_default_str();
  app.add_option("--match-timeout", args->timeout_s, "Seconds to wait for the physics server's subscriber")->check(CLI::PositiveNumber)->capture_default_str();
  return ParseOrExitCode(app, argc, argv);
}

// The command of `words`; its numeric arguments parsed (a word that is not a number: exit 2).
std::optional<int> CommandFromWords(const std::vector<std::string>& words, WorldCommandInput* cmd) {
  cmd->target = words[0] == "-" ? "" : words[0];
  cmd->command = words[1];
  for (std::size_t i = 2; i < words.size(); ++i) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(words[i], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != words[i].size()) {
      std::fprintf(stderr, "swarmbox-physics: --send-command: argument %zu (%s) is not a number\n", i - 1, words[i].c_str());
      return kExitBadInput;
    }
    cmd->args.push_back(v);
  }
  return std::nullopt;
}

}  // namespace

std::optional<int> ParseOrExitCode(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : kExitBadInput;
  }
  return std::nullopt;
}

int RunSendCommand(int argc, char** argv) {
  SendArgs args;
  if (std::optional<int> rc = ParseSendArgs(argc, argv, &args)) return *rc;
  WorldCommandInput cmd;
  if (std::optional<int> rc = CommandFromWords(args.words, &cmd)) return *rc;
  bus::ParticipantConfig pc;
  pc.backend = args.middleware;
  pc.domain_id = args.domain;
  pc.interface = args.interface;
  SendOptions so;
  so.match_timeout = std::chrono::milliseconds(static_cast<std::int64_t>(args.timeout_s * 1000));
  const Status s = SendWorldCommand(pc, cmd, so);
  if (!s) {
    std::fprintf(stderr, "swarmbox-physics: %s\n", s.error().ToString().c_str());
    return s.error().code() == ErrorCode::kInvalidArgument ? kExitBadInput : kExitNotSent;
  }
  std::printf("node=physics-command event=world_command_sent command=%s target=%s args=%zu\n", cmd.command.c_str(),
              args.words[0].c_str(), cmd.args.size());
  return 0;
}

}  // namespace swarmbox::physics
