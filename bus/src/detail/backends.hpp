// Factories of the two backends; each is defined in its own library target
// (swarmbox_bus_cyclone, swarmbox_bus_fastdds), linked privately into swarmbox_bus.
#pragma once

#include <memory>
#include <string>

#include "swarmbox/bus/detail/backend.hpp"
#include "swarmbox/bus/participant.hpp"

namespace swarmbox::bus::detail {

// `config` has been validated (backend name, domain id range, interface exists); `ipv4` is the
// interface's address. Errors: kInvalidArgument when this process already bound the domain to
// another interface, kInternal when the middleware refuses.
Result<std::unique_ptr<ParticipantBackend>> CreateCycloneBackend(const ParticipantConfig& config,
                                                                 const std::string& ipv4);
Result<std::unique_ptr<ParticipantBackend>> CreateFastddsBackend(const ParticipantConfig& config,
                                                                 const std::string& ipv4);

}  // namespace swarmbox::bus::detail
