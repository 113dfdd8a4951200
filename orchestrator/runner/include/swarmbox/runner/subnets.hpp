// Per-trial subnets: each trial gets a `sim` and a `mesh` /24 from a private pool, chosen so that
// parallel trials on one host do not collide: the first candidate pair is derived from the run id
// (a hash), candidates that overlap a network already on the host are skipped, and a retry after a
// conflict at create time (another orchestrator won the race) moves on with `attempt` + 1.
//
// Pool: 10.200.0.0/14, 512 pairs (10.200.0.0/24 + 10.200.1.0/24, 10.200.2.0/24 + ...).
// Fixed addresses inside a /24: .1 gateway, .2 physics server, .3 ground station/recorder,
// .10 + i drone i.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::runner {

struct Ipv4Net {
  std::uint32_t base = 0;  // network address, host byte order
  int prefix = 24;

  // "10.200.4.0/24"; nullopt on anything else (host bits set are masked off).
  static std::optional<Ipv4Net> Parse(std::string_view cidr);
  std::string ToString() const;
  // The address `host` inside the network ("10.200.4.12" for 12); aborts when out of range.
  std::string Host(std::uint32_t host) const;
  bool Overlaps(const Ipv4Net& other) const;
};

struct TrialSubnets {
  Ipv4Net sim;
  Ipv4Net mesh;
};

inline constexpr std::uint32_t kGatewayHost = 1;
inline constexpr std::uint32_t kPhysicsHost = 2;
inline constexpr std::uint32_t kGroundHost = 3;
inline constexpr std::uint32_t kFirstDroneHost = 10;

// `key` picks the first candidate pair (the runner passes "<run id>/<trial id>").
// `taken`: CIDRs of networks already on the host (unparseable entries are ignored). Fails with
// kUnavailable when the whole pool is taken.
Result<TrialSubnets> PickSubnets(std::string_view key, int attempt,
                                 const std::vector<std::string>& taken);

}  // namespace swarmbox::runner
