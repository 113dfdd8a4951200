#include "swarmbox/docker/cancel_token.hpp"

#include <utility>

namespace swarmbox::docker {

void CancelToken::Cancel() {
  std::lock_guard<std::mutex> lock(mu_);
  if (cancelled_.exchange(true, std::memory_order_acq_rel)) return;
  // Wakers run under mu_ so that Unregister() can promise "not running and never again".
  for (auto& [id, wake] : wakers_) wake();
}

std::uint64_t CancelToken::Register(std::function<void()> wake) {
  std::lock_guard<std::mutex> lock(mu_);
  const std::uint64_t id = next_id_++;
  if (cancelled_.load(std::memory_order_acquire)) {
    wake();
    return id;
  }
  wakers_.emplace(id, std::move(wake));
  return id;
}

void CancelToken::Unregister(std::uint64_t id) {
  std::lock_guard<std::mutex> lock(mu_);
  wakers_.erase(id);
}

}  // namespace swarmbox::docker
