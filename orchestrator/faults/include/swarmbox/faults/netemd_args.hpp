// NetemdArgs: the command line of swarmbox-netemd, built by the radio plan and parsed by the daemon
// (one definition, so the two cannot drift).
//
//   swarmbox-netemd run --queue 0 --delay-us 100000 --jitter-us 20000 --distribution normal
//                       --correlation 0.25 --reorder 0 --reorder-correlation 0 --reorder-gap 0
//                       --seed 42 --queue-maxlen 4096 [--pidfile /run/swarmbox-netemd-0.pid]
//                       [--daemonize] [--ge-p 0.02 --ge-r 0.25 --ge-loss-bad 0.9 --ge-loss-good 0]
//                       [--corrupt 0.1]
//   swarmbox-netemd stop --pidfile /run/swarmbox-netemd-0.pid   # SIGTERM, wait until it is gone
//   swarmbox-netemd sleep                                       # a sidecar's pid 1: reaps, waits
//
// `run` binds NFQUEUE `--queue`, holds each packet for its sampled delay and then accepts it. With
// --daemonize it forks once the queue is bound and the parent exits 0 (so a `docker exec` returns
// when the delayer is ready). On SIGTERM it accepts every held packet at once and exits 0. With the
// --ge-* flags (all four, netem's gemodel p, r, 1-h, 1-k) it drops each packet a Gilbert-Elliott
// model (gilbert_elliott_loss.hpp) says is lost, before delaying the rest: on egress, yet the
// sender sees no error (its send() returned when the packet was queued). With --corrupt P it flips
// one random bit in a fraction P of the packets (packet_corruptor.hpp), checksums left as they are.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/faults/delay_scheduler.hpp"

namespace swarmbox::faults {

// The longest queue the daemon asks the kernel for [packets].
inline constexpr std::uint32_t kNetemdMaxQueueLen = 1u << 20;

struct NetemdArgs {
  std::uint16_t queue = 0;
  DelaySettings delay;
  std::uint64_t seed = 0;
  std::optional<GilbertElliott> gilbert_elliott;  // bursty loss, drawn per packet; none = no loss
  double corrupt = 0.0;               // fraction of packets with one bit flipped; 0 = none
  std::uint32_t queue_maxlen = 1024;  // packets the kernel may hold for us before dropping
  std::string pidfile;                // "" = none
  bool daemonize = false;
  bool operator==(const NetemdArgs&) const = default;
};

// {program, "run", "--queue", ...}.
std::vector<std::string> NetemdRunArgv(const std::string& program, const NetemdArgs& args);
// {program, "stop", "--pidfile", pidfile}.
std::vector<std::string> NetemdStopArgv(const std::string& program, const std::string& pidfile);
// Parses the words after "run". Errors name the flag and what it expects.
Result<NetemdArgs> ParseNetemdRunArgs(const std::vector<std::string>& words);

}  // namespace swarmbox::faults
