#include "swarmbox/raft_service/payload_inbox.hpp"

#include <algorithm>
#include <iterator>

namespace swarmbox::raft_service {

PayloadInbox::PayloadInbox(std::size_t capacity) : capacity_(std::max<std::size_t>(1, capacity)) {}

void PayloadInbox::Push(std::span<const std::uint8_t> bytes) {
  {
    std::lock_guard<std::mutex> lk(mu_);
    if (items_.size() >= capacity_) {
      items_.pop_front();
      ++drops_;
    }
    items_.emplace_back(bytes.begin(), bytes.end());
  }
  cv_.notify_one();
}

std::size_t PayloadInbox::Drain(std::vector<raft::Bytes>* out) {
  std::lock_guard<std::mutex> lk(mu_);
  const std::size_t n = items_.size();
  out->insert(out->end(), std::make_move_iterator(items_.begin()),
              std::make_move_iterator(items_.end()));
  items_.clear();
  return n;
}

bool PayloadInbox::WaitUntil(std::chrono::steady_clock::time_point deadline) const {
  std::unique_lock<std::mutex> lk(mu_);
  return cv_.wait_until(lk, deadline, [this] { return !items_.empty(); });
}

std::size_t PayloadInbox::size() const {
  std::lock_guard<std::mutex> lk(mu_);
  return items_.size();
}

std::uint64_t PayloadInbox::drops() const {
  std::lock_guard<std::mutex> lk(mu_);
  return drops_;
}

}  // namespace swarmbox::raft_service
