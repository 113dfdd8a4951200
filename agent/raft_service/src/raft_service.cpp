#include "swarmbox/raft_service/raft_service.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace swarmbox::raft_service {
namespace {

// The clock in whole microseconds: a step time such as 25 * 0.004 s lands on the 100 ms tick
// whatever the last bit of the double says.
std::int64_t ToMicros(double t_s) { return std::llround(t_s * 1e6); }

}  // namespace

void PrintLineToStdout(const std::string& line) {
  std::fwrite(line.data(), 1, line.size(), stdout);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

RaftService::RaftService(RaftServiceConfig config, const raft::Clock& clock, LineSink out)
    : config_(std::move(config)), clock_(clock), out_(std::move(out)) {}

RaftService::~RaftService() { driver_.reset(); }

Result<std::unique_ptr<RaftService>> RaftService::Start(const RaftServiceConfig& config,
                                                        raft::Transport& transport,
                                                        const raft::Clock& clock, LineSink out,
                                                        std::unique_ptr<raft::StateMachine> machine) {
  if (auto c = config.driver.ToRaftConfig(); !c) return c.error().Context("raft service");
  if (config.data_dir.empty()) {
    return Error(ErrorCode::kInvalidArgument, "raft service: no data directory");
  }
  if (!out) out = PrintLineToStdout;
  std::unique_ptr<RaftService> s(new RaftService(config, clock, std::move(out)));
  raft::FileSystem* fs = s->config_.file_system;
  if (fs == nullptr) {
    s->own_fs_ = std::make_unique<raft::PosixFileSystem>();
    fs = s->own_fs_.get();
  }
  auto wal = raft::WalStorage::Open(*fs, s->config_.data_dir);
  if (!wal) return std::move(wal).error().Context("raft service: opening the WAL");
  s->wal_ = std::move(*wal);

  RaftService* raw = s.get();
  auto driver = raft::NodeDriver::Open(s->config_.driver, *s->wal_, transport, clock,
                                       [raw](const LogEvent& e) { raw->out_(e.str()); },
                                       std::move(machine));
  if (!driver) return std::move(driver).error().Context("raft service: opening the node");
  s->driver_ = std::move(*driver);

  const raft::DriverConfig& d = s->config_.driver;  // validated by ToRaftConfig above
  s->tick_us_ = static_cast<std::int64_t>(d.tick_ms) * 1000;
  s->max_catch_up_ticks_ = std::max(1, d.heartbeat_ms / d.tick_ms);
  s->next_tick_us_ = ToMicros(clock.NowS()) + s->tick_us_;
  return s;
}

void RaftService::OnPayload(std::span<const std::uint8_t> bytes) {
  if (driver_->stopped()) return;
  if (driver_->Receive(bytes)) return;
  // Another cluster's or a damaged datagram: the node goes on. A storage failure while handling
  // it shows as stopped() (and in health()).
  if (!driver_->stopped()) ++protocol_errors_;
}

Status RaftService::Tick() {
  if (driver_->stopped()) return *driver_->stop_error();
  const std::int64_t now_us = ToMicros(clock_.NowS());
  if (now_us < next_tick_us_) return Ok{};
  const std::int64_t due = (now_us - next_tick_us_) / tick_us_ + 1;
  const std::int64_t run = std::min<std::int64_t>(due, max_catch_up_ticks_);
  next_tick_us_ += due * tick_us_;  // the grid stays start + n * tick whatever was dropped
  dropped_ticks_ += static_cast<std::uint64_t>(due - run);
  for (std::int64_t i = 0; i < run; ++i) {
    ++ticks_;
    if (Status s = driver_->Tick(); !s) return s;
  }
  return Ok{};
}

Status RaftService::Propose(const raft::MissionCommand& command) {
  return driver_->Propose(command);
}

Status RaftService::ProposeBytes(raft::Bytes data) { return driver_->Propose(std::move(data)); }

Status RaftService::Campaign() { return driver_->Campaign(); }

Status RaftService::health() const {
  if (driver_->stopped()) return *driver_->stop_error();
  return Ok{};
}

double RaftService::next_tick_s() const { return static_cast<double>(next_tick_us_) * 1e-6; }

}  // namespace swarmbox::raft_service
