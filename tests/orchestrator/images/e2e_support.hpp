// Helpers for the end-to-end tests against the real Docker engine: a connected client that fails
// the test loudly when there is no engine, unique run ids, labelled networks on a free subnet, and
// a thread-safe collector of streamed log lines.
#pragma once

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "swarmbox/docker/docker_client.hpp"

namespace swarmbox::testing {

inline std::unique_ptr<docker::DockerClient> ConnectOrFail() {
  auto client = docker::DockerClient::Connect({.socket_path = docker::DefaultSocketPath(),
                                               .connect_timeout = std::chrono::seconds(5),
                                               .request_timeout = std::chrono::seconds(60)});
  if (!client) {
    ADD_FAILURE() << "these e2e tests need a Docker engine: " << client.error().ToString();
    return nullptr;
  }
  return std::move(*client);
}

inline std::string UniqueRunId(const std::string& prefix) {
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  return prefix + "-" + std::to_string(getpid()) + "-" +
         std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(now).count() % 100000000);
}

// Creates a network on the first free 10.213.k.0/24 (other engineers' networks may hold some).
// Returns the id and sets *subnet_prefix to "10.213.k.".
inline Result<std::string> CreateFreeNetwork(docker::DockerApi& api, docker::NetworkSpec spec,
                                             std::string* subnet_prefix) {
  std::optional<Error> last;
  for (int attempt = 0; attempt < 40; ++attempt) {
    const int k = 100 + static_cast<int>((static_cast<unsigned>(getpid()) + static_cast<unsigned>(attempt) * 7u) % 150u);
    const std::string prefix = "10.213." + std::to_string(k) + ".";
    spec.subnet = prefix + "0/24";
    spec.gateway = prefix + "1";
    auto id = api.CreateNetwork(spec);
    if (id) {
      *subnet_prefix = prefix;
      return id;
    }
    last = id.error();
    if (id.error().message().find("overlap") == std::string::npos) break;
  }
  return *last;
}

// Collects lines from a stream callback (any thread) and lets the test wait for one.
class LineLog {
 public:
  docker::LogLineFn Collector() {
    return [this](const docker::LogLine& line) {
      std::lock_guard<std::mutex> lock(mu_);
      if (lines_.empty()) first_line_at_ = std::chrono::steady_clock::now();
      lines_.push_back(line);
      cv_.notify_all();
    };
  }
  bool WaitFor(const std::string& text, std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mu_);
    return cv_.wait_for(lock, timeout, [&] { return HasLocked(text); });
  }
  bool Has(const std::string& text) {
    std::lock_guard<std::mutex> lock(mu_);
    return HasLocked(text);
  }
  std::vector<docker::LogLine> lines() {
    std::lock_guard<std::mutex> lock(mu_);
    return lines_;
  }
  std::chrono::steady_clock::time_point first_line_at() {
    std::lock_guard<std::mutex> lock(mu_);
    return first_line_at_;
  }
  std::string Dump() {
    std::lock_guard<std::mutex> lock(mu_);
    std::string out;
    for (const auto& l : lines_) out += (l.stream == docker::StreamKind::kStderr ? "E| " : "O| ") + l.text + "\n";
    return out;
  }

 private:
  bool HasLocked(const std::string& text) const {
    for (const auto& l : lines_) {
      if (l.text == text) return true;
    }
    return false;
  }
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<docker::LogLine> lines_;
  std::chrono::steady_clock::time_point first_line_at_{};
};

}  // namespace swarmbox::testing
