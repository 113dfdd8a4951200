#include "detail/net_interface.hpp"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstring>
#include <set>
#include <vector>

namespace swarmbox::bus::detail {

namespace {

std::string Ipv4Text(const sockaddr* addr) {
  sockaddr_in sin{};
  std::memcpy(&sin, addr, sizeof(sin));
  char buf[INET_ADDRSTRLEN] = {};
  return inet_ntop(AF_INET, &sin.sin_addr, buf, sizeof(buf)) != nullptr ? std::string(buf) : std::string();
}

// The error for an interface without an IPv4 address (`exists`) or one that is not there, with
// the interfaces that would do.
Error NoIpv4Error(std::string_view name, bool exists, const std::vector<std::string>& with_ipv4) {
  std::string accepted;
  for (const auto& n : with_ipv4) accepted += (accepted.empty() ? "" : ", ") + n;
  if (accepted.empty()) accepted = "(none)";
  return Error(ErrorCode::kNotFound,
               "network interface '" + std::string(name) +
                   (exists ? "' has no IPv4 address" : "' does not exist") +
                   "; interfaces with an IPv4 address here: " + accepted,
               "getifaddrs");
}

}  // namespace

Result<std::string> ResolveInterfaceIpv4(std::string_view name) {
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) {
    return Error(ErrorCode::kIo, std::string("getifaddrs failed: ") + std::strerror(errno),
                 "getifaddrs");
  }
  std::string found;
  bool exists = false;
  std::vector<std::string> with_ipv4;
  std::set<std::string> seen;
  for (const ifaddrs* it = list; it != nullptr; it = it->ifa_next) {
    if (it->ifa_name == nullptr) continue;
    const std::string ifname = it->ifa_name;
    const bool is_ipv4 = it->ifa_addr != nullptr && it->ifa_addr->sa_family == AF_INET;
    if (ifname == name) {
      exists = true;
      if (is_ipv4 && found.empty()) found = Ipv4Text(it->ifa_addr);
    }
    if (is_ipv4 && seen.insert(ifname).second) with_ipv4.push_back(ifname);
  }
  freeifaddrs(list);
  if (!found.empty()) return found;
  return NoIpv4Error(name, exists, with_ipv4);
}

}  // namespace swarmbox::bus::detail
