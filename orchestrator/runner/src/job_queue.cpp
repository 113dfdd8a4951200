#include "swarmbox/runner/job_queue.hpp"

#include <algorithm>

namespace swarmbox::runner {

JobQueue::JobQueue(int max_threads) : max_threads_(std::max(1, max_threads)) {}

JobQueue::~JobQueue() { Close(); }

void JobQueue::Post(Job job) {
  std::unique_lock lock(mu_);
  if (closing_) {
    lock.unlock();
    job(true);
    return;
  }
  jobs_.push_back(std::move(job));
  if (idle_ == 0 && static_cast<int>(workers_.size()) < max_threads_) {
    workers_.emplace_back([this] { Work(); });
  } else {
    cv_.notify_one();
  }
}

void JobQueue::Work() {
  std::unique_lock lock(mu_);
  while (true) {
    ++idle_;
    cv_.wait(lock, [this] { return closing_ || !jobs_.empty(); });
    --idle_;
    if (jobs_.empty()) return;  // closing
    Job next = std::move(jobs_.front());
    jobs_.pop_front();
    const bool cancelled = closing_;
    lock.unlock();
    next(cancelled);
    lock.lock();
  }
}

void JobQueue::Close() {
  std::vector<std::thread> workers;
  {
    std::lock_guard lock(mu_);
    closing_ = true;
    workers.swap(workers_);
  }
  cv_.notify_all();
  for (std::thread& t : workers) t.join();
}

int JobQueue::threads() const {
  std::lock_guard lock(mu_);
  return static_cast<int>(workers_.size());
}

}  // namespace swarmbox::runner
