#include "swarmbox/runner/detail/engine_pipelines.hpp"

namespace swarmbox::runner::detail {

using dsl::Verdict;

std::shared_ptr<std::promise<Verdict>> CreatesAhead::Add(const std::string& component,
                                                         int priority) {
  auto promise = std::make_shared<std::promise<Verdict>>();
  std::lock_guard lock(mu_);
  creates_[component] = promise->get_future().share();
  build_traced_by_create_.insert(component);
  ++unfinished_[priority];
  return promise;
}

std::optional<std::shared_future<Verdict>> CreatesAhead::Find(const std::string& component) const {
  std::lock_guard lock(mu_);
  auto it = creates_.find(component);
  if (it == creates_.end()) return std::nullopt;
  return it->second;
}

void CreatesAhead::WaitForEarlierLevels(int priority) {
  std::unique_lock lock(mu_);
  finished_cv_.wait(lock, [&] {
    for (const auto& [p, n] : unfinished_) {
      if (p < priority && n > 0) return false;
    }
    return true;
  });
}

void CreatesAhead::Finished(int priority, const std::shared_ptr<std::promise<Verdict>>& promise,
                            const Verdict& verdict) {
  {
    std::lock_guard lock(mu_);
    --unfinished_[priority];
  }
  finished_cv_.notify_all();
  promise->set_value(verdict);
}

bool CreatesAhead::TakeBuildTrace(const std::string& component) {
  std::lock_guard lock(mu_);
  return build_traced_by_create_.erase(component) > 0;
}

void CreatesAhead::Forget(const std::string& component) {
  std::lock_guard lock(mu_);
  creates_.erase(component);
}

std::vector<std::shared_future<Verdict>> CreatesAhead::All() const {
  std::lock_guard lock(mu_);
  std::vector<std::shared_future<Verdict>> all;
  for (const auto& [component, created] : creates_) all.push_back(created);
  return all;
}

BackgroundStops::~BackgroundStops() { Join(); }

std::unique_ptr<BackgroundStops::Pending> BackgroundStops::Launch(std::function<Verdict()> finish) {
  auto pending = std::make_unique<Pending>();
  Pending* raw = pending.get();
  raw->thread = std::thread([raw, finish = std::move(finish)] { raw->verdict = finish(); });
  return pending;
}

void BackgroundStops::Keep(std::unique_ptr<Pending> pending) {
  std::lock_guard lock(mu_);
  pending_.push_back(std::move(pending));
}

void BackgroundStops::Join() {
  std::lock_guard joining(join_mu_);
  std::vector<std::unique_ptr<Pending>> pending;
  {
    std::lock_guard lock(mu_);
    pending.swap(pending_);
  }
  Verdict v;
  for (auto& p : pending) {
    if (p->thread.joinable()) p->thread.join();
    v.KeepWorse(p->verdict);
  }
  std::lock_guard lock(mu_);
  verdict_.KeepWorse(v);
}

Verdict BackgroundStops::Take() {
  Join();
  std::lock_guard lock(mu_);
  Verdict v = verdict_;
  verdict_ = Verdict::Success();
  return v;
}

}  // namespace swarmbox::runner::detail
