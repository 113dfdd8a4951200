#include "raft_host.hpp"

#include <algorithm>
#include <utility>

#include "swarmbox/bus/topics.hpp"
#include "swarmbox/mission/demo_mission.hpp"

namespace swarmbox::agent {

Result<std::vector<std::string>> ParseMembers(std::string_view text, std::string_view self) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string item(text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (item.empty()) return Error(ErrorCode::kInvalidArgument, "--members '" + std::string(text) + "': empty name");
    if (Status s = bus::ValidateDroneName(item); !s) return s.error().Context("--members");
    if (std::find(out.begin(), out.end(), item) != out.end()) {
      return Error(ErrorCode::kInvalidArgument, "--members: '" + item + "' listed twice");
    }
    out.push_back(item);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (std::find(out.begin(), out.end(), self) == out.end()) {
    return Error(ErrorCode::kInvalidArgument,
                 "--members '" + std::string(text) + "' does not include this drone ('" + std::string(self) + "')");
  }
  return out;
}

std::string DefaultRaftDir(std::string_view name) { return "/tmp/swarmbox-raft/" + std::string(name); }

Result<std::unique_ptr<RaftHost>> RaftHost::Start(const RaftHostOptions& options, bus::Participant& mesh,
                                                  std::FILE* log) {
  if (options.propose_every_ms < 0) return Error(ErrorCode::kInvalidArgument, "--propose-every-ms must be >= 0");
  if (options.raft_dir.empty()) return Error(ErrorCode::kInvalidArgument, "--raft-dir must not be empty");
  std::unique_ptr<RaftHost> host(new RaftHost(options));
  mission::RaftServiceConfig rc;
  rc.driver.self = options.self;
  rc.driver.members = options.members;
  rc.driver.seed = options.seed;
  rc.driver.tick_ms = options.tick_ms;
  rc.driver.heartbeat_ms = options.heartbeat_ms;
  rc.driver.election_timeout_ms = options.election_timeout_ms;
  rc.data_dir = options.raft_dir;
  rc.file_system = options.file_system;
  // One fprintf per line: stdio's lock keeps it whole next to the control loop's events.
  auto service = mission::RaftService::Start(rc, mesh, host->clock_, [log](const std::string& line) {
    std::fprintf(log, "%s\n", line.c_str());
    std::fflush(log);
  });
  if (!service) return service.error().Context("starting raft");
  host->service_ = std::move(*service);
  const auto now = std::chrono::steady_clock::now();
  host->next_propose_ = now + std::chrono::milliseconds(options.propose_every_ms);
  return host;
}

Status RaftHost::Poll() {
  using namespace std::chrono;
  if (stopped_) return service_->health();
  const auto now = steady_clock::now();
  if (now < next_poll_) return Ok{};
  next_poll_ = now + milliseconds(20);
  if (service_->WaitStopped(milliseconds(0))) {
    stopped_ = true;
    return service_->health();
  }
  if (options_.propose_every_ms > 0 && now >= next_propose_) {
    next_propose_ = now + milliseconds(options_.propose_every_ms);
    if (service_->is_leader()) {
      if (auto cmd = mission::NextDemoCommand(service_->mission(), service_->self())) {
        (void)service_->Propose(*cmd);  // kUnavailable (leadership just lost): the next round retries
      }
    }
  }
  return Ok{};
}

}  // namespace swarmbox::agent
