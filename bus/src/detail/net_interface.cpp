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
      if (is_ipv4 && found.empty()) {
        sockaddr_in sin{};
        std::memcpy(&sin, it->ifa_addr, sizeof(sin));
        char buf[INET_ADDRSTRLEN] = {};
        if (inet_ntop(AF_INET, &sin.sin_addr, buf, sizeof(buf)) != nullptr) found = buf;
      }
    }
    if (is_ipv4 && seen.insert(ifname).second) with_ipv4.push_back(ifname);
  }
  freeifaddrs(list);
  if (!found.empty()) return found;
  std::string accepted;
  for (const auto& n : with_ipv4) accepted += (accepted.empty() ? "" : ", ") + n;
  if (accepted.empty()) accepted = "(none)";
  if (exists) {
    return Error(ErrorCode::kNotFound,
                 "network interface '" + std::string(name) +
                     "' has no IPv4 address; interfaces with an IPv4 address here: " + accepted,
                 "getifaddrs");
  }
  return Error(ErrorCode::kNotFound,
               "network interface '" + std::string(name) +
                   "' does not exist; interfaces with an IPv4 address here: " + accepted,
               "getifaddrs");
}

}  // namespace swarmbox::bus::detail
