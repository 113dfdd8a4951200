// swarmbox view RUN_DIR [--addr ADDR:PORT]: replays RUN_DIR/recording.mcap in the built-in page.
// Every message of the recording (camera frames included) goes into a record::LiveServer as its
// history (mode "replay": the page starts at the first message and plays or scrubs); Foxglove can
// connect to the same address. Prints `view: http://ADDR:PORT/` on stdout and serves until Ctrl-C
// or SIGTERM, then exits 0. Exit 2: no recording, a recording that cannot be read, a bad --addr;
// 3: the address cannot be listened on (port in use, not an address of this host).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <thread>
#include <vector>

#include "commands.hpp"
#include "interrupt.hpp"
#include "swarmbox/record/live_server.hpp"
#include "swarmbox/record/mcap.hpp"

namespace swarmbox::cli {
namespace {

// How often the serving loop looks for Ctrl-C.
constexpr std::chrono::milliseconds kStopPoll{100};

Result<std::pair<std::string, int>> ParseListenAddress(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size()) {
    return Error(ErrorCode::kInvalidArgument, "expected ADDR:PORT (e.g. 127.0.0.1:8765)", text);
  }
  const std::string port_text = text.substr(colon + 1);
  int port = 0;
  for (char c : port_text) {
    if (c < '0' || c > '9' || port > 65535) {
      return Error(ErrorCode::kInvalidArgument, "the port is not a number in 0..65535", text);
    }
    port = port * 10 + (c - '0');
  }
  if (port > 65535) return Error(ErrorCode::kInvalidArgument, "the port is not a number in 0..65535", text);
  return std::make_pair(text.substr(0, colon), port);
}

int Refuse(const std::string& message, int exit_code) {
  std::cerr << "swarmbox view: " << message << "\n";
  return exit_code;
}

record::LiveOptions ReplayOptions(const std::pair<std::string, int>& addr, const std::string& run_dir) {
  record::LiveOptions options;
  options.address = addr.first;
  options.port = addr.second;
  options.name = "swarmbox view " + std::filesystem::path(run_dir).filename().string();
  options.mode = "replay";
  options.history_bytes = std::numeric_limits<std::size_t>::max();  // the whole recording
  options.history_images = true;
  return options;
}

// Every channel and message of the recording into the server's history.
Status LoadHistory(record::LiveServer& server, const record::McapReader& reader) {
  std::vector<record::ChannelId> ids;  // the reader's channel id -> the server's
  for (const record::ChannelSpec& spec : reader.channels()) {
    if (spec.topic.empty()) {  // an id the file does not use
      ids.push_back(0);
      continue;
    }
    auto id = server.AddChannel(spec);
    if (!id) return id.error();
    ids.push_back(*id);
  }
  Status written = Ok{};
  const Status read = reader.ForEach([&](const record::McapMessage& m) {
    if (!written || m.channel >= ids.size() || ids[m.channel] == 0) return;
    written = server.Write(ids[m.channel], m.log_time_ns, m.data);
  });
  return !read ? read : written;
}

// Says what is served and where, then serves until Ctrl-C or SIGTERM.
void ServeUntilStopped(const record::LiveServer& server, const record::McapReader& reader, const std::string& path) {
  const auto& stop = InstallInterruptHandlers();
  std::fprintf(stderr, "swarmbox view: %s: %llu messages on %zu channels, t = %.1f .. %.1f s; Ctrl-C stops\n",
               path.c_str(), static_cast<unsigned long long>(reader.message_count()), reader.channels().size(),
               static_cast<double>(reader.start_ns()) / 1e9, static_cast<double>(reader.end_ns()) / 1e9);
  std::cout << "view: " << server.url() << std::endl;
  while (!stop.load()) std::this_thread::sleep_for(kStopPoll);
  std::cerr << "swarmbox view: " << InterruptName() << ", stopped\n";
}

}  // namespace

int ViewCommand(const ViewArgs& args) {
  auto addr = ParseListenAddress(args.addr);
  if (!addr) return Refuse("--addr " + addr.error().ToString(), kExitUsage);
  const std::string path = (std::filesystem::path(args.run_dir) / "recording.mcap").string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return Refuse(path + ": no recording there (" + args.run_dir +
                      " is not a trial folder, or the trial ran with --no-record / record.enabled false)",
                  kExitUsage);
  }
  auto reader = record::McapReader::Open(path);
  if (!reader) return Refuse(reader.error().ToString(), kExitUsage);
  auto server = record::LiveServer::Start(ReplayOptions(*addr, args.run_dir));
  if (!server) {
    return Refuse(server.error().ToString(),
                  server.error().code() == ErrorCode::kInvalidArgument ? kExitUsage : kExitInfrastructure);
  }
  if (Status loaded = LoadHistory(**server, *reader); !loaded) {
    return Refuse(path + ": " + loaded.error().ToString(), kExitUsage);
  }
  ServeUntilStopped(**server, *reader, path);
  return kExitOk;
}

}  // namespace swarmbox::cli
