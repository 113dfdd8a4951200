// TcpUnixForwarder: a test's own TCP endpoint on 127.0.0.1 in front of a unix socket (the Docker
// engine's), so DOCKER_HOST=tcp://127.0.0.1:<port> can be tested against the real engine without
// reconfiguring dockerd or installing socat. Loopback only; one thread per connection pumping
// both ways until either side closes.
//
//   auto fwd = TcpUnixForwarder::Start("/var/run/docker.sock");
//   setenv("DOCKER_HOST", ("tcp://127.0.0.1:" + std::to_string((*fwd)->port())).c_str(), 1);
//   ... (*fwd)->connections() > 0 proves the traffic went through it.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::testing {

class TcpUnixForwarder {
 public:
  static Result<std::unique_ptr<TcpUnixForwarder>> Start(std::string unix_path);
  ~TcpUnixForwarder();  // stops accepting, closes every connection, joins the threads
  TcpUnixForwarder(const TcpUnixForwarder&) = delete;
  TcpUnixForwarder& operator=(const TcpUnixForwarder&) = delete;

  int port() const { return port_; }
  int connections() const { return connections_.load(); }

 private:
  TcpUnixForwarder() = default;
  void AcceptLoop();
  void Pump(int client, int engine);

  std::string unix_path_;
  int listen_fd_ = -1;
  int wake_[2] = {-1, -1};  // a pipe: written to stop the threads
  int port_ = 0;
  std::atomic<int> connections_{0};
  std::thread acceptor_;
  std::mutex mu_;
  std::vector<std::thread> pumps_;
};

}  // namespace swarmbox::testing
