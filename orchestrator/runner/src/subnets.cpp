#include "swarmbox/runner/subnets.hpp"

#include <charconv>

namespace swarmbox::runner {

namespace {

constexpr std::uint32_t kPoolBase = (10u << 24) | (200u << 16);  // 10.200.0.0
constexpr std::uint32_t kPoolPairs = 512;                        // /14 = 1024 /24s

std::uint32_t Mask(int prefix) {
  return prefix == 0 ? 0u : ~std::uint32_t{0} << (32 - prefix);
}

// FNV-1a: stable across platforms and runs, unlike std::hash.
std::uint32_t Fnv1a(std::string_view s) {
  std::uint32_t h = 2166136261u;
  for (char c : s) {
    h ^= static_cast<std::uint8_t>(c);
    h *= 16777619u;
  }
  return h;
}

}  // namespace

std::optional<Ipv4Net> Ipv4Net::Parse(std::string_view cidr) {
  std::uint32_t addr = 0;
  const char* p = cidr.data();
  const char* end = cidr.data() + cidr.size();
  for (int i = 0; i < 4; ++i) {
    unsigned octet = 0;
    auto r = std::from_chars(p, end, octet);
    if (r.ec != std::errc() || octet > 255) return std::nullopt;
    addr = (addr << 8) | octet;
    p = r.ptr;
    if (i < 3) {
      if (p == end || *p != '.') return std::nullopt;
      ++p;
    }
  }
  int prefix = 32;
  if (p != end) {
    if (*p != '/') return std::nullopt;
    ++p;
    auto r = std::from_chars(p, end, prefix);
    if (r.ec != std::errc() || r.ptr != end || prefix < 0 || prefix > 32) return std::nullopt;
  }
  return Ipv4Net{addr & Mask(prefix), prefix};
}

std::string Ipv4Net::ToString() const {
  return std::to_string(base >> 24) + "." + std::to_string((base >> 16) & 255u) + "." +
         std::to_string((base >> 8) & 255u) + "." + std::to_string(base & 255u) + "/" +
         std::to_string(prefix);
}

std::string Ipv4Net::Host(std::uint32_t host) const {
  SWARMBOX_CHECK(host > 0 && (host & Mask(prefix)) == 0);
  const std::uint32_t a = base | host;
  return std::to_string(a >> 24) + "." + std::to_string((a >> 16) & 255u) + "." +
         std::to_string((a >> 8) & 255u) + "." + std::to_string(a & 255u);
}

bool Ipv4Net::Overlaps(const Ipv4Net& other) const {
  const std::uint32_t m = Mask(std::min(prefix, other.prefix));
  return (base & m) == (other.base & m);
}

Result<TrialSubnets> PickSubnets(std::string_view key, int attempt,
                                 const std::vector<std::string>& taken) {
  std::vector<Ipv4Net> used;
  for (const std::string& t : taken) {
    if (auto n = Ipv4Net::Parse(t)) used.push_back(*n);
  }
  auto free = [&](const Ipv4Net& n) {
    for (const Ipv4Net& u : used) {
      if (u.Overlaps(n)) return false;
    }
    return true;
  };
  const std::uint32_t start = Fnv1a(key) % kPoolPairs;
  int skip = attempt;  // a retry moves past the pairs that lost a race before
  for (std::uint32_t i = 0; i < kPoolPairs; ++i) {
    const std::uint32_t pair = (start + i) % kPoolPairs;
    TrialSubnets s{{kPoolBase + (pair * 2) * 256u, 24}, {kPoolBase + (pair * 2 + 1) * 256u, 24}};
    if (!free(s.sim) || !free(s.mesh)) continue;
    if (skip-- > 0) continue;
    return s;
  }
  return Error(ErrorCode::kUnavailable,
               "no free subnet pair left in the pool 10.200.0.0/14 (" + std::to_string(used.size()) +
                   " networks on the host)");
}

}  // namespace swarmbox::runner
