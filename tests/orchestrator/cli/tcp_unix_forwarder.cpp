#include "tcp_unix_forwarder.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace swarmbox::testing {

namespace {

Error SysError(const std::string& what) {
  return Error(ErrorCode::kIo, what + ": " + std::strerror(errno), "tcp->unix forwarder");
}

// Writes all of buf; false when the peer is gone.
bool WriteAll(int fd, const char* buf, ssize_t n) {
  while (n > 0) {
    const ssize_t w = ::send(fd, buf, static_cast<size_t>(n), MSG_NOSIGNAL);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    buf += w;
    n -= w;
  }
  return true;
}

}  // namespace

Result<std::unique_ptr<TcpUnixForwarder>> TcpUnixForwarder::Start(std::string unix_path) {
  std::unique_ptr<TcpUnixForwarder> f(new TcpUnixForwarder());
  f->unix_path_ = std::move(unix_path);
  if (::pipe(f->wake_) != 0) return SysError("pipe");
  f->listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (f->listen_fd_ < 0) return SysError("socket");
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  if (::bind(f->listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) return SysError("bind 127.0.0.1");
  if (::listen(f->listen_fd_, 64) != 0) return SysError("listen");
  socklen_t len = sizeof addr;
  if (::getsockname(f->listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len) != 0) return SysError("getsockname");
  f->port_ = ntohs(addr.sin_port);
  f->acceptor_ = std::thread([p = f.get()] { p->AcceptLoop(); });
  return f;
}

TcpUnixForwarder::~TcpUnixForwarder() {
  if (wake_[1] >= 0) {
    const char c = 'x';
    (void)::write(wake_[1], &c, 1);
  }
  if (acceptor_.joinable()) acceptor_.join();
  std::vector<std::thread> pumps;
  {
    std::lock_guard lock(mu_);
    pumps.swap(pumps_);
  }
  for (std::thread& t : pumps) t.join();
  for (int fd : {listen_fd_, wake_[0], wake_[1]}) {
    if (fd >= 0) ::close(fd);
  }
}

void TcpUnixForwarder::AcceptLoop() {
  for (;;) {
    pollfd fds[2] = {{listen_fd_, POLLIN, 0}, {wake_[0], POLLIN, 0}};
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (fds[1].revents != 0) return;
    const int client = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) continue;
    const int engine = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, unix_path_.c_str(), sizeof addr.sun_path - 1);
    if (engine < 0 || ::connect(engine, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      if (engine >= 0) ::close(engine);
      ::close(client);
      continue;
    }
    ++connections_;
    std::lock_guard lock(mu_);
    pumps_.emplace_back([this, client, engine] { Pump(client, engine); });
  }
}

void TcpUnixForwarder::Pump(int client, int engine) {
  char buf[64 * 1024];
  bool open[2] = {true, true};  // client->engine, engine->client
  while (open[0] || open[1]) {
    pollfd fds[3] = {{client, static_cast<short>(open[0] ? POLLIN : 0), 0},
                     {engine, static_cast<short>(open[1] ? POLLIN : 0), 0},
                     {wake_[0], POLLIN, 0}};
    if (::poll(fds, 3, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (fds[2].revents != 0) break;
    for (int side = 0; side < 2; ++side) {
      if (!open[side] || fds[side].revents == 0) continue;
      const int from = side == 0 ? client : engine;
      const int to = side == 0 ? engine : client;
      const ssize_t n = ::recv(from, buf, sizeof buf, 0);
      if (n > 0 && WriteAll(to, buf, n)) continue;
      if (n < 0 && errno == EINTR) continue;
      // EOF (or an error) on one side: pass the half-close on, as a TCP proxy does.
      open[side] = false;
      ::shutdown(to, SHUT_WR);
    }
  }
  ::close(client);
  ::close(engine);
}

}  // namespace swarmbox::testing
