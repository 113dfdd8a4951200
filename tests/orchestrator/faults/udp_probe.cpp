#include "udp_probe.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sched.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <sstream>
#include <thread>

namespace swarmbox::faults::testing {
namespace {

std::int64_t ClockUs(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}

std::string Errno(const std::string& doing) { return doing + ": " + std::strerror(errno); }

// A file descriptor closed when it goes out of scope.
class Fd {
 public:
  explicit Fd(int fd = -1) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) close(fd_);
  }
  int get() const { return fd_; }

 private:
  int fd_;
};

// A UDP socket created inside namespace `ns` (the calling thread goes back to its own namespace).
Result<int> SocketIn(const std::string& ns) {
  Fd self(open("/proc/self/ns/net", O_RDONLY | O_CLOEXEC));
  if (self.get() < 0) return Error(ErrorCode::kIo, Errno("open /proc/self/ns/net"));
  const std::string path = "/run/netns/" + ns;
  Fd target(open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (target.get() < 0) return Error(ErrorCode::kIo, Errno("open " + path));
  if (setns(target.get(), CLONE_NEWNET) != 0) return Error(ErrorCode::kIo, Errno("setns " + path));
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  const int socket_errno = errno;
  if (setns(self.get(), CLONE_NEWNET) != 0) {
    // This thread is stranded in the other namespace: nothing after this can be trusted.
    std::fprintf(stderr, "udp_probe: setns back from %s failed: %s\n", path.c_str(), std::strerror(errno));
    std::abort();
  }
  if (fd < 0)
    return Error(ErrorCode::kIo, std::string("socket in ") + ns + ": " + std::strerror(socket_errno));
  return fd;
}

}  // namespace

double ProbeSample::Mean() const {
  double s = 0;
  for (double d : delay_ms) s += d;
  return s / static_cast<double>(delay_ms.size());
}

double ProbeSample::StdDev() const {
  const double m = Mean();
  double s = 0;
  for (double d : delay_ms) s += (d - m) * (d - m);
  return std::sqrt(s / static_cast<double>(delay_ms.size() - 1));
}

double ProbeSample::Quantile(double q) const {
  if (delay_ms.empty()) return std::nan("");
  std::vector<double> v = delay_ms;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

Result<ProbeSample> MeasureOneWay(const ProbeOptions& o) {
  if (o.payload_bytes < 16) return Error(ErrorCode::kInvalidArgument, "probe payload under 16 bytes");
  if (o.count < 0) return Error(ErrorCode::kInvalidArgument, "negative probe count");
  auto tx_fd = SocketIn(o.from_netns);
  if (!tx_fd) return tx_fd.error();
  Fd tx(*tx_fd);
  auto rx_fd = SocketIn(o.to_netns);
  if (!rx_fd) return rx_fd.error();
  Fd rx(*rx_fd);

  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(o.port);
  if (inet_pton(AF_INET, o.to_addr.c_str(), &to.sin_addr) != 1) {
    return Error(ErrorCode::kInvalidArgument, "not an IPv4 address: " + o.to_addr);
  }
  if (bind(rx.get(), reinterpret_cast<sockaddr*>(&to), sizeof to) != 0) {
    return Error(ErrorCode::kIo, Errno("bind " + o.to_addr + " in " + o.to_netns));
  }
  timeval tv{0, 100000};
  setsockopt(rx.get(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  // 4 MB each way, past net.core.[rw]mem_max where this process may (root: the FORCE options), so a
  // burst after a stall of the receiver is queued rather than dropped by the socket.
  int big = 4 << 20;
  if (setsockopt(rx.get(), SOL_SOCKET, SO_RCVBUFFORCE, &big, sizeof big) != 0) {
    setsockopt(rx.get(), SOL_SOCKET, SO_RCVBUF, &big, sizeof big);
  }
  if (setsockopt(tx.get(), SOL_SOCKET, SO_SNDBUFFORCE, &big, sizeof big) != 0) {
    setsockopt(tx.get(), SOL_SOCKET, SO_SNDBUF, &big, sizeof big);
  }
  int on = 1;
  if (setsockopt(rx.get(), SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0) {
    return Error(ErrorCode::kIo, Errno("SO_TIMESTAMPNS"));
  }

  ProbeSample sample;
  std::atomic<bool> done{false};
  std::map<std::uint32_t, double> got;
  std::thread receiver([&] {
    std::vector<char> buf(o.payload_bytes + 1);  // one byte more: a longer datagram is not ours
    std::int64_t quiet_since = 0;
    for (;;) {
      iovec iov{buf.data(), buf.size()};
      alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
      msghdr hdr{};
      hdr.msg_iov = &iov;
      hdr.msg_iovlen = 1;
      hdr.msg_control = control;
      hdr.msg_controllen = sizeof control;
      const ssize_t n = recvmsg(rx.get(), &hdr, 0);
      const std::int64_t now = ClockUs(CLOCK_REALTIME);
      if (n == static_cast<ssize_t>(o.payload_bytes)) {
        std::int64_t arrived = now;
        for (cmsghdr* c = CMSG_FIRSTHDR(&hdr); c != nullptr; c = CMSG_NXTHDR(&hdr, c)) {
          if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMPNS) {
            timespec ts{};
            std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
            arrived = static_cast<std::int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
          }
        }
        std::int64_t head[2];
        std::memcpy(head, buf.data(), sizeof head);
        const auto seq = static_cast<std::uint32_t>(head[0]);
        const double delay = static_cast<double>(arrived - head[1]) / 1000.0;
        got[seq] = delay;
        sample.arrivals.push_back({seq, delay, arrived});
        ++sample.datagrams;
        quiet_since = 0;
        continue;
      }
      if (!done) continue;
      if (quiet_since == 0) quiet_since = now;
      if (now - quiet_since > o.quiet_us) break;
    }
  });
  std::vector<char> msg(o.payload_bytes, 0);
  const std::int64_t start = ClockUs(CLOCK_MONOTONIC);
  for (int i = 0; i < o.count; ++i) {
    const std::int64_t due = start + i * o.spacing_us;
    // One sleep to the due time (not a poll: in a user-mode Linux guest each system call is costly).
    const timespec until{static_cast<time_t>(due / 1000000), static_cast<long>(due % 1000000) * 1000};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, nullptr) == EINTR) {
    }
    sample.max_send_late_us = std::max(sample.max_send_late_us, ClockUs(CLOCK_MONOTONIC) - due);
    const std::int64_t head[2] = {i, ClockUs(CLOCK_REALTIME)};
    std::memcpy(msg.data(), head, sizeof head);
    if (sendto(tx.get(), msg.data(), msg.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to) ==
        static_cast<ssize_t>(msg.size())) {
      ++sample.sent;
    }
  }
  done = true;
  receiver.join();
  for (const auto& [seq, d] : got) {
    sample.delay_ms.push_back(d);
    sample.seqs.push_back(seq);
  }
  return sample;
}

std::int64_t SnmpReceiveErrors(std::string_view snmp) {
  // Each group is a header line ("Udp: InDatagrams NoPorts InErrors ...") then a value line.
  std::int64_t total = 0;
  std::istringstream lines{std::string(snmp)};
  std::string names, values;
  while (std::getline(lines, names) && std::getline(lines, values)) {
    const std::string group = names.substr(0, names.find(':'));
    const char* counter = group == "Ip" ? "InHdrErrors" : group == "Udp" ? "InErrors" : nullptr;
    if (counter == nullptr) continue;
    std::istringstream n(names), v(values);
    std::string name, value;
    while (n >> name && v >> value) {
      if (name == counter) total += std::stoll(value);
    }
  }
  return total;
}

Result<std::int64_t> ReceiveErrors(CommandRunner& runner, const std::string& ns) {
  auto out = runner.Run({"ip", "netns", "exec", ns, "cat", "/proc/net/snmp"});
  if (!out) return out.error();
  if (out->exit_code != 0) {
    return Error(ErrorCode::kIo, "reading /proc/net/snmp in " + ns + " failed: " + out->stderr_text);
  }
  return SnmpReceiveErrors(out->stdout_text);
}

}  // namespace swarmbox::faults::testing
