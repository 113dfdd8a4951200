#include "swarmbox/mission/raft_service.hpp"

#include <cstdio>
#include <utility>
#include <vector>

namespace swarmbox::mission {

void PrintLineToStdout(const std::string& line) {
  std::fwrite(line.data(), 1, line.size(), stdout);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

RaftService::RaftService(RaftServiceConfig config, LineSink out)
    : config_(std::move(config)), out_(std::move(out)) {}

Result<std::unique_ptr<RaftService>> RaftService::Start(const RaftServiceConfig& config,
                                                        bus::Participant& mesh,
                                                        const raft::Clock& sim_clock,
                                                        LineSink out) {
  if (auto c = config.driver.ToRaftConfig(); !c) return c.error().Context("raft service");
  if (config.data_dir.empty()) {
    return Error(ErrorCode::kInvalidArgument, "raft service: no data directory");
  }
  if (!out) out = PrintLineToStdout;
  std::unique_ptr<RaftService> s(new RaftService(config, std::move(out)));
  raft::FileSystem* fs = s->config_.file_system;
  if (fs == nullptr) {
    s->own_fs_ = std::make_unique<raft::PosixFileSystem>();
    fs = s->own_fs_.get();
  }
  auto wal = raft::WalStorage::Open(*fs, s->config_.data_dir);
  if (!wal) return std::move(wal).error().Context("raft service: opening the WAL");
  s->wal_ = std::move(*wal);

  RaftService* raw = s.get();
  // A writer per member (RaftRadio: reordering on the radio must not become extra loss).
  auto radio = RaftRadio::Create(mesh, s->config_.driver.self, s->config_.driver.members,
                                 [raw](std::span<const std::uint8_t> b) { raw->OnPayload(b); });
  if (!radio) return std::move(radio).error().Context("raft service");
  s->radio_ = std::move(*radio);

  auto driver = raft::NodeDriver::Open(s->config_.driver, *s->wal_, *s->radio_, sim_clock,
                                       [raw](const LogEvent& e) { raw->out_(e.str()); });
  if (!driver) return std::move(driver).error().Context("raft service: opening the node");
  s->driver_ = std::move(*driver);
  s->thread_ = std::thread([raw] { raw->Run(); });
  return s;
}

RaftService::~RaftService() {
  {
    std::lock_guard<std::mutex> lk(inbox_mu_);
    quit_ = true;
  }
  inbox_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  radio_.reset();  // no callback into OnPayload after this
  std::lock_guard<std::mutex> lk(mu_);
  driver_.reset();
}

void RaftService::OnPayload(std::span<const std::uint8_t> bytes) {
  {
    std::lock_guard<std::mutex> lk(inbox_mu_);
    if (quit_) return;
    if (inbox_.size() >= config_.max_inbox) {
      inbox_.pop_front();
      ++inbox_drops_;
    }
    inbox_.emplace_back(bytes.begin(), bytes.end());
  }
  inbox_cv_.notify_one();
}

void RaftService::MarkStopped() {
  if (stop_error_ || !driver_->stopped()) return;
  stop_error_ = *driver_->stop_error();
  stopped_cv_.notify_all();
}

void RaftService::Run() {
  using Clock = std::chrono::steady_clock;
  const auto tick = std::chrono::milliseconds(config_.driver.tick_ms);
  auto next_tick = Clock::now() + tick;
  std::vector<raft::Bytes> batch;
  while (true) {
    {
      std::unique_lock<std::mutex> lk(inbox_mu_);
      inbox_cv_.wait_until(lk, next_tick, [this] { return quit_ || !inbox_.empty(); });
      if (quit_) return;
      batch.assign(std::make_move_iterator(inbox_.begin()), std::make_move_iterator(inbox_.end()));
      inbox_.clear();
    }
    std::lock_guard<std::mutex> lk(mu_);
    for (const raft::Bytes& b : batch) {
      if (driver_->Receive(b)) continue;
      if (driver_->stopped()) break;
      ++protocol_errors_;  // another cluster's or a damaged datagram: the node goes on
    }
    batch.clear();
    const auto now = Clock::now();
    if (!driver_->stopped() && now >= next_tick) {
      (void)driver_->Tick();  // a failure shows as stopped() below
      // Ticks are wall-clock time for Raft: after a stall (a loaded machine) one tick is taken,
      // not a burst that would make every timer fire at once.
      next_tick += tick;
      if (next_tick <= now) next_tick = now + tick;
    }
    if (driver_->stopped()) {
      MarkStopped();
      return;
    }
  }
}

Status RaftService::Propose(const raft::MissionCommand& command) {
  std::lock_guard<std::mutex> lk(mu_);
  if (stop_error_) return *stop_error_;
  Status s = driver_->Propose(command);
  MarkStopped();
  return s;
}

Status RaftService::Campaign() {
  std::lock_guard<std::mutex> lk(mu_);
  if (stop_error_) return *stop_error_;
  Status s = driver_->Campaign();
  MarkStopped();
  return s;
}

raft::MissionState RaftService::mission() const {
  std::lock_guard<std::mutex> lk(mu_);
  return driver_->mission();
}

std::string RaftService::leader() const {
  std::lock_guard<std::mutex> lk(mu_);
  return driver_->leader();
}

bool RaftService::is_leader() const {
  std::lock_guard<std::mutex> lk(mu_);
  return driver_->is_leader();
}

std::uint64_t RaftService::term() const {
  std::lock_guard<std::mutex> lk(mu_);
  return driver_->raft().term();
}

std::uint64_t RaftService::commit_index() const {
  std::lock_guard<std::mutex> lk(mu_);
  return driver_->raft().log().committed();
}

Status RaftService::health() const {
  std::lock_guard<std::mutex> lk(mu_);
  if (stop_error_) return *stop_error_;
  return Ok{};
}

bool RaftService::WaitStopped(std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lk(mu_);
  return stopped_cv_.wait_for(lk, timeout, [this] { return stop_error_.has_value(); });
}

std::uint64_t RaftService::protocol_errors() const {
  std::lock_guard<std::mutex> lk(mu_);
  return protocol_errors_;
}

std::uint64_t RaftService::inbox_drops() const {
  std::lock_guard<std::mutex> lk(inbox_mu_);
  return inbox_drops_;
}

}  // namespace swarmbox::mission
