#include "swarmbox/runner/log_hub.hpp"

#include "swarmbox/runner/end_matcher.hpp"

namespace swarmbox::runner {

void LogHub::Push(HubItem item) {
  {
    std::lock_guard lock(mu_);
    auto it = pending_.find(item.component);
    if (it != pending_.end()) {
      Pending& p = it->second;
      if (item.kind == HubItem::Kind::kStreamEnd) {
        p.ended = true;
      } else if (p.pattern && !p.ready && SearchLogPattern(*p.pattern, item.text)) {
        p.ready = true;
      }
    }
    queue_.push_back(std::move(item));
  }
  cv_.notify_all();
}

std::vector<HubItem> LogHub::Drain(std::chrono::milliseconds wait) {
  std::unique_lock lock(mu_);
  cv_.wait_for(lock, wait, [this] { return !queue_.empty(); });
  std::vector<HubItem> out(std::make_move_iterator(queue_.begin()),
                           std::make_move_iterator(queue_.end()));
  queue_.clear();
  return out;
}

void LogHub::Expect(const std::string& component, std::regex pattern) {
  std::lock_guard lock(mu_);
  pending_[component] = Pending{std::move(pattern), false, false};
}

LogHub::Readiness LogHub::WaitReady(const std::string& component,
                                    std::chrono::milliseconds timeout,
                                    const std::atomic<bool>* interrupted) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::unique_lock lock(mu_);
  while (true) {
    Pending& p = pending_[component];
    if (p.ready) return Readiness::kReady;
    if (p.ended) return Readiness::kStreamEnded;
    if (interrupted != nullptr && interrupted->load()) return Readiness::kInterrupted;
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) return Readiness::kTimedOut;
    // Short slices so an interrupt is seen promptly.
    cv_.wait_for(lock, std::min<std::chrono::steady_clock::duration>(deadline - now,
                                                                     std::chrono::milliseconds(100)));
  }
}

}  // namespace swarmbox::runner
