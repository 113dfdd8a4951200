#include "swarmbox/runner/log_follower.hpp"

#include <cstdio>
#include <filesystem>
#include <utility>
#include <vector>

namespace swarmbox::runner {

LogFollower::LogFollower(docker::DockerApi& api, LogHub& hub, Clock& clock, Options options)
    : options_(std::move(options)) {
  thread_ = std::thread([this, &api, &hub, &clock] { Follow(api, hub, clock); });
}

LogFollower::~LogFollower() { Finish(std::chrono::milliseconds(0)); }

void LogFollower::Follow(docker::DockerApi& api, LogHub& hub, Clock& clock) {
  const Options& o = options_;
  std::uint64_t to_skip = o.skip_lines;
  std::FILE* out = std::fopen(o.log_path.c_str(), "ab");
  docker::LogOptions opts;
  opts.follow = true;
  Status s = api.FollowLogs(
      o.container_id, opts,
      [&](const docker::LogLine& line) {
        if (to_skip > 0) {  // delivered by an earlier follower (the container ran before)
          --to_skip;
          return;
        }
        if (out != nullptr) {
          std::fwrite(line.text.data(), 1, line.text.size(), out);
          std::fputc('\n', out);
          std::fflush(out);
        }
        lines_.fetch_add(1);
        hub.Push({HubItem::Kind::kLine, o.component, line.text, clock.NowS() - o.start_wall_s,
                  o.generation});
      },
      &cancel_);
  if (out != nullptr) std::fclose(out);
  std::string why;
  if (!s && s.error().code() != ErrorCode::kCancelled) why = s.error().ToString();
  if (out == nullptr) why = "cannot write " + o.log_path;
  hub.Push({HubItem::Kind::kStreamEnd, o.component, why, clock.NowS() - o.start_wall_s,
            o.generation});
  clean_end_.store(s.ok());
  {
    std::lock_guard lock(end_mu_);
    ended_.store(true);
  }
  end_cv_.notify_all();
  if (o.on_end) o.on_end();
}

std::uint64_t LogFollower::Finish(std::chrono::milliseconds grace) {
  if (grace.count() > 0) {
    // The stream ends by itself once the container stopped; give it a moment to deliver the rest.
    std::unique_lock lock(end_mu_);
    end_cv_.wait_for(lock, grace, [this] { return ended_.load(); });
  }
  cancel_.Cancel();
  std::lock_guard join(join_mu_);
  if (thread_.joinable()) thread_.join();
  return lines_.load();
}

LogFollowers::LogFollowers(docker::DockerApi& api, LogHub& hub, Clock& clock, Options options)
    : api_(api), hub_(hub), clock_(clock), options_(std::move(options)) {}

LogFollowers::~LogFollowers() {
  std::map<std::string, std::unique_ptr<LogFollower>> all;
  {
    std::lock_guard lock(mu_);
    all.swap(followers_);
  }
  for (auto& [component, f] : all) f->Cancel();  // all at once, then joined one by one
  for (auto& [component, f] : all) f->Finish(std::chrono::milliseconds(0));
}

std::unique_ptr<LogFollower> LogFollowers::Take(const std::string& component) {
  std::lock_guard lock(mu_);
  auto it = followers_.find(component);
  if (it == followers_.end()) return nullptr;
  std::unique_ptr<LogFollower> f = std::move(it->second);
  followers_.erase(it);
  return f;
}

std::uint64_t LogFollowers::Start(const std::string& component, const std::string& container_id,
                                  std::uint64_t skip_lines) {
  std::uint64_t previous_lines = 0;
  if (std::unique_ptr<LogFollower> previous = Take(component)) {
    previous_lines = previous->Finish(std::chrono::milliseconds(0));
  }
  LogFollower::Options o;
  o.component = component;
  o.container_id = container_id;
  o.log_path = (std::filesystem::path(options_.logs_dir) / (component + ".log")).string();
  o.start_wall_s = options_.start_wall_s;
  o.skip_lines = skip_lines;
  o.on_end = options_.on_end;
  {
    std::lock_guard lock(mu_);
    o.generation = next_generation_++;
    generations_[component] = o.generation;
  }
  auto follower = std::make_unique<LogFollower>(api_, hub_, clock_, std::move(o));
  std::lock_guard lock(mu_);
  followers_[component] = std::move(follower);
  return previous_lines;
}

std::uint64_t LogFollowers::Finish(const std::string& component, std::chrono::milliseconds grace) {
  std::unique_ptr<LogFollower> f = Take(component);
  return f ? f->Finish(grace) : 0;
}

bool LogFollowers::IsCurrent(const HubItem& item) const {
  std::lock_guard lock(mu_);
  auto it = generations_.find(item.component);
  return it != generations_.end() && it->second == item.generation;
}

bool LogFollowers::EndedByItself(const std::string& component) const {
  std::lock_guard lock(mu_);
  auto it = followers_.find(component);
  return it != followers_.end() && it->second->ended_by_itself();
}

}  // namespace swarmbox::runner
