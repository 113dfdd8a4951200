#include "nfqueue_delayer.hpp"

#include <arpa/inet.h>
#include <linux/netfilter.h>
#include <poll.h>
#include <signal.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

extern "C" {
#include <libnetfilter_queue/libnetfilter_queue.h>
}

namespace swarmbox::faults {
namespace {

Error SysError(const std::string& call) {
  return Error(ErrorCode::kIo, call + ": " + std::strerror(errno), "swarmbox-netemd");
}

// One read of the queue socket: the largest netlink message the queue sends (64 KiB).
constexpr std::size_t kReceiveBufferBytes = std::size_t{1} << 16;

}  // namespace

std::int64_t MonotonicUs() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}

NfqueueDelayer::NfqueueDelayer(const NetemdArgs& args) : args_(args), scheduler_(args.delay, args.seed) {
  if (args.gilbert_elliott) loss_.emplace(*args.gilbert_elliott, args.seed);
  if (args.corrupt > 0.0) corruptor_.emplace(args.corrupt, args.seed);
}

NfqueueDelayer::~NfqueueDelayer() {
  if (queue_ != nullptr) nfq_destroy_queue(queue_);
  if (handle_ != nullptr) nfq_close(handle_);
}

Result<std::unique_ptr<NfqueueDelayer>> NfqueueDelayer::Open(const NetemdArgs& args) {
  std::unique_ptr<NfqueueDelayer> d(new NfqueueDelayer(args));
  d->handle_ = nfq_open();
  if (d->handle_ == nullptr) return SysError("nfq_open (is nfnetlink_queue available, and CAP_NET_ADMIN held?)");
  // Old kernels need the per-family binding; newer ones ignore it. Failures here are not fatal.
  nfq_unbind_pf(d->handle_, AF_INET);
  nfq_bind_pf(d->handle_, AF_INET);
  d->queue_ = nfq_create_queue(d->handle_, args.queue, &NfqueueDelayer::OnPacket, d.get());
  if (d->queue_ == nullptr) {
    return SysError("nfq_create_queue " + std::to_string(args.queue) + " (is another daemon bound to it?)");
  }
  // Corruption needs the packet's bytes; otherwise metadata (the id) is all we need.
  if (args.corrupt > 0.0) {
    if (nfq_set_mode(d->queue_, NFQNL_COPY_PACKET, 0xffff) < 0) return SysError("nfq_set_mode COPY_PACKET");
  } else if (nfq_set_mode(d->queue_, NFQNL_COPY_META, 0) < 0) {
    return SysError("nfq_set_mode COPY_META");
  }
  if (nfq_set_queue_maxlen(d->queue_, args.queue_maxlen) < 0) return SysError("nfq_set_queue_maxlen");
  // Room for a burst of queue messages while we sleep until the next release.
  nfnl_rcvbufsiz(nfq_nfnlh(d->handle_), 8u * 1024u * 1024u);
  return d;
}

int NfqueueDelayer::OnPacket(nfq_q_handle* /*queue*/, ::nfgenmsg* /*msg*/, ::nfq_data* data, void* self) {
  auto* d = static_cast<NfqueueDelayer*>(self);
  const nfqnl_msg_packet_hdr* header = nfq_get_msg_packet_hdr(data);
  if (header == nullptr) return 0;
  const std::uint32_t id = ntohl(header->packet_id);
  ++d->stats_.packets;
  if (d->loss_ && d->loss_->Lose()) {
    if (nfq_set_verdict(d->queue_, id, NF_DROP, 0, nullptr) < 0) ++d->stats_.verdict_errors;
    ++d->stats_.dropped;
    return 0;
  }
  if (d->corruptor_) {
    unsigned char* payload = nullptr;
    const int length = nfq_get_payload(data, &payload);
    if (length > 0) {
      if (auto bit = d->corruptor_->Choose(static_cast<std::size_t>(length))) {
        std::vector<std::uint8_t> bytes(payload, payload + length);
        FlipBit(bytes, *bit);
        d->corrupted_[id] = std::move(bytes);
        ++d->stats_.corrupted;
      }
    }
  }
  const std::int64_t now_us = MonotonicUs();
  d->scheduler_.Admit(id, now_us);
  return 0;
}

void NfqueueDelayer::Accept(const HeldPacket& packet, std::int64_t now_us) {
  int sent = 0;
  if (auto it = corrupted_.find(packet.id); it != corrupted_.end()) {
    sent = nfq_set_verdict(queue_, packet.id, NF_ACCEPT, static_cast<std::uint32_t>(it->second.size()),
                           it->second.data());
    corrupted_.erase(it);
  } else {
    sent = nfq_set_verdict(queue_, packet.id, NF_ACCEPT, 0, nullptr);
  }
  if (sent < 0) ++stats_.verdict_errors;
  hold_sum_ms_ += static_cast<double>(now_us - packet.admitted_us) / 1000.0;
}

void NfqueueDelayer::ReleaseDue(std::int64_t now_us) {
  while (auto next = scheduler_.NextReleaseUs()) {
    if (*next > now_us) break;
    Accept(scheduler_.PopNext(), now_us);
  }
}

namespace {

// How long ppoll may sleep: until the next release, or with no packet held, until woken (nullptr).
timespec* TimeUntilRelease(std::optional<std::int64_t> next_release_us, std::int64_t now_us,
                           timespec* storage) {
  if (!next_release_us) return nullptr;
  const std::int64_t wait_us = std::max<std::int64_t>(0, *next_release_us - now_us);
  storage->tv_sec = static_cast<time_t>(wait_us / 1000000);
  storage->tv_nsec = static_cast<long>((wait_us % 1000000) * 1000);
  return storage;
}

}  // namespace

Status NfqueueDelayer::DrainQueueSocket(int fd, std::vector<char>& buf) {
  for (;;) {
    const ssize_t len = ::recv(fd, buf.data(), buf.size(), MSG_DONTWAIT);
    if (len > 0) {
      nfq_handle_packet(handle_, buf.data(), static_cast<int>(len));
      continue;
    }
    if (len < 0 && errno == ENOBUFS) {
      ++stats_.receive_overruns;
      continue;
    }
    if (len < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return Ok{};
    return SysError("recv on the netfilter queue socket");
  }
}

void NfqueueDelayer::ReleaseAllAndSummarize() {
  const std::int64_t now_us = MonotonicUs();
  while (!scheduler_.empty()) Accept(scheduler_.PopNext(), now_us);
  stats_.reordered = scheduler_.reordered();
  const std::uint64_t held = stats_.packets - stats_.dropped;
  stats_.mean_hold_ms = held > 0 ? hold_sum_ms_ / static_cast<double>(held) : 0.0;
}

Status NfqueueDelayer::Run() {
  sigset_t mask;
  sigemptyset(&mask);
  sigaddset(&mask, SIGTERM);
  sigaddset(&mask, SIGINT);
  if (sigprocmask(SIG_BLOCK, &mask, nullptr) != 0) return SysError("sigprocmask");
  const int sfd = signalfd(-1, &mask, SFD_CLOEXEC | SFD_NONBLOCK);
  if (sfd < 0) return SysError("signalfd");
  const int fd = nfq_fd(handle_);
  std::vector<char> buf(kReceiveBufferBytes);
  Status result;
  for (bool stop = false; !stop;) {
    const std::int64_t now_us = MonotonicUs();
    ReleaseDue(now_us);
    timespec timeout{};
    timespec* timeout_ptr = TimeUntilRelease(scheduler_.NextReleaseUs(), now_us, &timeout);
    pollfd fds[2] = {{fd, POLLIN, 0}, {sfd, POLLIN, 0}};
    const int n = ::ppoll(fds, 2, timeout_ptr, nullptr);
    if (n < 0) {
      if (errno == EINTR) continue;
      result = SysError("ppoll");
      break;
    }
    if ((fds[1].revents & POLLIN) != 0) stop = true;
    if ((fds[0].revents & POLLIN) != 0) {
      if (Status drained = DrainQueueSocket(fd, buf); !drained) {
        result = drained;
        stop = true;
      }
    }
  }
  ReleaseAllAndSummarize();  // leaving: nothing stays held
  ::close(sfd);
  return result;
}

}  // namespace swarmbox::faults
