#include "raft_host.hpp"

#include <algorithm>
#include <functional>
#include <utility>

#include "swarmbox/bus/topics.hpp"
#include "swarmbox/raft_service/demo_mission.hpp"
#include "swarmbox/raft_service/raft_envelope.hpp"

namespace swarmbox::agent {

namespace {

// The comma-separated names of `flag`: none empty, each passing `check`, none twice (checked in
// that order for each name, in the list's order).
Result<std::vector<std::string>> ParseNameList(std::string_view text, const std::string& flag,
                                               const std::function<Status(const std::string&)>& check) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string item(text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (item.empty())
      return Error(ErrorCode::kInvalidArgument, flag + " '" + std::string(text) + "': empty name");
    SWARMBOX_TRY(check(item));
    if (std::find(out.begin(), out.end(), item) != out.end()) {
      return Error(ErrorCode::kInvalidArgument, flag + ": '" + item + "' listed twice");
    }
    out.push_back(item);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

Result<std::vector<std::string>> ParseMembers(std::string_view text, std::string_view self) {
  auto out = ParseNameList(text, "--members", [](const std::string& item) -> Status {
    if (Status s = bus::ValidateDroneName(item); !s) return s.error().Context("--members");
    return Ok{};
  });
  if (!out) return out.error();
  if (std::find(out->begin(), out->end(), self) == out->end()) {
    return Error(ErrorCode::kInvalidArgument,
                 "--members '" + std::string(text) + "' does not include this drone ('" + std::string(self) + "')");
  }
  return out;
}

Result<std::vector<std::string>> ParseVoters(std::string_view text, const std::vector<std::string>& members) {
  return ParseNameList(text, "--raft-voters", [&members](const std::string& item) -> Status {
    if (std::find(members.begin(), members.end(), item) == members.end()) {
      return Error(ErrorCode::kInvalidArgument, "--raft-voters: '" + item + "' is not in --members");
    }
    return Ok{};
  });
}

std::string DefaultRaftDir(std::string_view name) { return "/tmp/swarmbox-raft/" + std::string(name); }

std::string RestampLine(std::string_view line, double t_s) {
  if (line.substr(0, 2) != "t=") return std::string(line);
  const std::size_t end = line.find(' ');
  char buf[32];
  std::snprintf(buf, sizeof buf, "t=%.3f", t_s);
  return std::string(buf) + std::string(end == std::string_view::npos ? std::string_view() : line.substr(end));
}

void RadioTransport::Send(const std::string& to, std::span<const std::uint8_t> bytes) {
  bus::RadioFrame f;
  f.to = to;
  f.raft_msg.push_back(raft_service::WrapRaftPayload(self_, to, bytes));
  radio_.Send(std::move(f));
}

Result<std::unique_ptr<RaftHost>> RaftHost::Start(const RaftHostOptions& options, radio::MeshRadio& radio,
                                                  const raft::Clock& clock, std::FILE* log,
                                                  const raft::Clock* event_clock,
                                                  std::unique_ptr<raft::StateMachine> machine) {
  if (options.propose_every_ms < 0) return Error(ErrorCode::kInvalidArgument, "--propose-every-ms must be >= 0");
  if (options.propose_every_ms > 0 && machine != nullptr &&
      dynamic_cast<const raft::MissionStateMachine*>(machine.get()) == nullptr) {
    return Error(ErrorCode::kInvalidArgument,
                 "--propose-every-ms proposes mission commands: it needs the mission state machine");
  }
  if (options.raft_dir.empty()) return Error(ErrorCode::kInvalidArgument, "--raft-dir must not be empty");
  std::unique_ptr<RaftHost> host(new RaftHost(options, radio, clock));
  raft_service::RaftServiceConfig rc;
  rc.driver.self = options.self;
  rc.driver.members = options.members;
  rc.driver.voters = options.voters;
  rc.driver.seed = options.seed;
  rc.driver.tick_ms = options.tick_ms;
  rc.driver.heartbeat_ms = options.heartbeat_ms;
  rc.driver.election_timeout_ms = options.election_timeout_ms;
  rc.data_dir = options.raft_dir;
  rc.file_system = options.file_system;
  auto service = raft_service::RaftService::Start(rc, host->transport_, clock, [log, event_clock](const std::string& line) {
    const std::string out = event_clock != nullptr ? RestampLine(line, event_clock->NowS()) : line;
    std::fprintf(log, "%s\n", out.c_str());
    std::fflush(log);
  }, std::move(machine));
  if (!service) return service.error().Context("starting raft");
  host->service_ = std::move(*service);
  host->next_propose_s_ = clock.NowS() + options.propose_every_ms * 1e-3;
  return host;
}

Status RaftHost::Step() {
  SWARMBOX_TRY(service_->Tick());
  if (options_.propose_every_ms > 0) {
    const double now = clock_.NowS();
    if (now >= next_propose_s_) {
      next_propose_s_ = now + options_.propose_every_ms * 1e-3;
      const raft::MissionState* mission = service_->FindMission();
      if (service_->is_leader() && mission != nullptr) {
        if (auto cmd = raft_service::NextDemoCommand(*mission, service_->self())) {
          (void)service_->Propose(*cmd);  // kUnavailable (leadership just lost): the next round retries
        }
      }
    }
  }
  return service_->health();
}

}  // namespace swarmbox::agent
