// Resolving a network interface name to the IPv4 address the backends bind to (getifaddrs).
#pragma once

#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"

namespace swarmbox::bus::detail {

// The first IPv4 address of interface `name`, e.g. "127.0.0.1" for "lo".
// kNotFound when no such interface exists or it has no IPv4 address; the message names the
// interfaces that do have one. kIo if getifaddrs fails.
Result<std::string> ResolveInterfaceIpv4(std::string_view name);

}  // namespace swarmbox::bus::detail
