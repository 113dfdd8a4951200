// NfqueueDelayer: swarmbox-netemd's I/O shell around DelayScheduler. Binds one NFQUEUE, admits each
// queued packet into the scheduler with the monotonic clock and accepts it when its release time
// comes (ppoll with microsecond timeouts). Metadata only is copied from the kernel; packets are
// modified only by --corrupt: then whole packets are copied from the kernel, and a packet the
// PacketCorruptor chooses has one bit flipped and keeps its modified bytes until its verdict
// (NF_ACCEPT with the new payload; checksums are not fixed, as netem does not). Random loss is
// iptables `statistic`'s job (on ingress); a Gilbert-Elliott model (bursty loss, --ge-*) is drawn
// here and its losses get NF_DROP at once.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/faults/delay_scheduler.hpp"
#include "swarmbox/faults/gilbert_elliott_loss.hpp"
#include "swarmbox/faults/netemd_args.hpp"
#include "swarmbox/faults/packet_corruptor.hpp"

struct nfq_handle;
struct nfq_q_handle;
struct nfq_data;
struct nfgenmsg;

namespace swarmbox::faults {

struct DelayerStats {
  std::uint64_t packets = 0;
  std::uint64_t reordered = 0;        // sent at once (reorder fraction)
  std::uint64_t dropped = 0;          // lost by the Gilbert-Elliott model (NF_DROP)
  std::uint64_t corrupted = 0;        // one bit flipped (--corrupt)
  std::uint64_t verdict_errors = 0;
  std::uint64_t receive_overruns = 0;  // ENOBUFS: the kernel dropped queue messages for us
  double mean_hold_ms = 0.0;          // actual hold time, admission to verdict
};

class NfqueueDelayer {
 public:
  ~NfqueueDelayer();
  // Binds the queue (needs CAP_NET_ADMIN in the namespace). Errors say which call failed and why.
  static Result<std::unique_ptr<NfqueueDelayer>> Open(const NetemdArgs& args);
  // Runs until SIGTERM/SIGINT (blocked and read through a signalfd set up here) or a fatal error;
  // then accepts every held packet at once.
  Status Run();
  const DelayerStats& stats() const { return stats_; }

 private:
  explicit NfqueueDelayer(const NetemdArgs& args);
  static int OnPacket(nfq_q_handle* queue, ::nfgenmsg* msg, ::nfq_data* data, void* self);
  void ReleaseDue(std::int64_t now_us);
  void Accept(const HeldPacket& packet, std::int64_t now_us);
  // Hands every message waiting on the queue socket to libnetfilter_queue; a failed recv is the error.
  Status DrainQueueSocket(int fd, std::vector<char>& buf);
  // Accepts every held packet now and fills the final stats (reordered, mean hold).
  void ReleaseAllAndSummarize();

  NetemdArgs args_;
  DelayScheduler scheduler_;
  std::optional<GilbertElliottLoss> loss_;
  std::optional<PacketCorruptor> corruptor_;
  std::unordered_map<std::uint32_t, std::vector<std::uint8_t>> corrupted_;  // packet id -> its new bytes
  nfq_handle* handle_ = nullptr;
  nfq_q_handle* queue_ = nullptr;
  DelayerStats stats_;
  double hold_sum_ms_ = 0.0;
};

std::int64_t MonotonicUs();

}  // namespace swarmbox::faults
