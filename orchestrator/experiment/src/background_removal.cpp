#include "swarmbox/experiment/background_removal.hpp"

#include <utility>

#include "swarmbox/docker/remove_labelled.hpp"

namespace swarmbox::experiment {

BackgroundRemover::BackgroundRemover(docker::DockerApi& api, std::string host)
    : api_(api), host_(std::move(host)) {}

BackgroundRemover::~BackgroundRemover() {
  Drain();
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void BackgroundRemover::Enqueue(Item item) {
  {
    std::lock_guard lock(mu_);
    if (item.batch) ++item.batch->pending;
    queue_.push_back(std::move(item));
    if (!thread_.joinable()) thread_ = std::thread([this] { Work(); });
  }
  cv_.notify_all();
}

void BackgroundRemover::RemoveContainer(std::string id, bool remove_volumes,
                                        const std::shared_ptr<Batch>& batch) {
  Item item;
  item.kind = Item::Kind::kContainer;
  item.id = std::move(id);
  item.remove_volumes = remove_volumes;
  item.batch = batch;
  Enqueue(std::move(item));
}

void BackgroundRemover::RemoveNetwork(std::string id, const std::shared_ptr<Batch>& batch) {
  Item item;
  item.kind = Item::Kind::kNetwork;
  item.id = std::move(id);
  item.batch = batch;
  Enqueue(std::move(item));
}

void BackgroundRemover::Flush(const std::shared_ptr<Batch>& batch) {
  std::unique_lock lock(mu_);
  cv_.wait(lock, [&] { return batch->pending == 0; });
}

void BackgroundRemover::Drain() {
  std::unique_lock lock(mu_);
  cv_.wait(lock, [&] { return queue_.empty() && !busy_; });
}

std::vector<std::string> BackgroundRemover::TakeProblems() {
  std::lock_guard lock(mu_);
  std::vector<std::string> out;
  out.swap(problems_);
  return out;
}

void BackgroundRemover::Work() {
  std::unique_lock lock(mu_);
  while (true) {
    cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, nothing left
    Item item = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    lock.unlock();
    Remove(item);
    lock.lock();
    busy_ = false;
    if (item.batch) --item.batch->pending;
    cv_.notify_all();
  }
}

void BackgroundRemover::Remove(const Item& item) {
  std::string problem;
  if (item.kind == Item::Kind::kContainer) {
    Status s = api_.RemoveContainer(item.id, /*force=*/true, item.remove_volumes);
    if (!s && s.error().code() != ErrorCode::kNotFound) {
      problem = host_ + ": removing container " + item.id + ": " + s.error().ToString();
    }
  } else {
    const Status s = docker::RemoveNetworkPatiently(api_, item.id);
    if (docker::IsStaleEndpointRefusal(s)) {
      problem = host_ + ": network " + item.id + " left on the engine: " + s.error().message() +
                " (" + docker::kStaleEndpointAdvice + ")";
    } else if (!s && s.error().code() != ErrorCode::kNotFound) {
      problem = host_ + ": removing network " + item.id + ": " + s.error().ToString();
    }
  }
  if (!problem.empty()) {
    std::lock_guard lock(mu_);
    problems_.push_back(std::move(problem));
  }
}

DeferredRemovalApi::DeferredRemovalApi(docker::DockerApi& inner, BackgroundRemover& remover)
    : inner_(inner), remover_(remover) {}

Result<std::string> DeferredRemovalApi::CreateNetwork(const docker::NetworkSpec& spec) {
  remover_.Flush(batch_);  // the same name may be waiting for its removal (another subnet pair)
  return inner_.CreateNetwork(spec);
}

Status DeferredRemovalApi::RemoveNetwork(std::string_view id) {
  remover_.RemoveNetwork(std::string(id), batch_);
  return Ok{};
}

Result<std::string> DeferredRemovalApi::CreateContainer(const docker::ContainerSpec& spec) {
  remover_.Flush(batch_);  // the same name may be waiting for its removal (a restart)
  return inner_.CreateContainer(spec);
}

Status DeferredRemovalApi::RemoveContainer(std::string_view id, bool /*force*/, bool remove_volumes) {
  remover_.RemoveContainer(std::string(id), remove_volumes, batch_);
  return Ok{};
}

}  // namespace swarmbox::experiment
