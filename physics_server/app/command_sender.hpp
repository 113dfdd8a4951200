// SendWorldCommand: the one-shot sender behind `swarmbox-physics --send-command` (how the
// orchestrator, which links no DDS, carries out sensor and environment faults: a docker exec of
// that program in the physics container). It joins the sim bus, waits until the server's
// world-command subscriber has matched, publishes one WorldCommand (kLockstep: reliable, as the
// server subscribes) and lingers so the reliable protocol delivers it before the participant goes.
//
//   bus::ParticipantConfig pc{.backend = "cyclonedds", .domain_id = 0, .interface = "eth0"};
//   Status s = SendWorldCommand(pc, {"scout_1", "gps_dropout", {3.0}}, {});
//
// There is no acknowledgement on the bus: success means "a server matched and the sample was
// written to it"; the server logs `event=world_command` (or `event=world_command_rejected`).
#pragma once

#include <chrono>

#include "sim_server.hpp"
#include "swarmbox/bus/participant.hpp"

namespace swarmbox::physics {

struct SendOptions {
  // How long to wait for the server's subscriber to match.
  std::chrono::milliseconds match_timeout{5000};
  // After matching, before writing: matching is seen per side, and the server's volatile reader
  // misses a sample written before it has matched this writer in turn.
  std::chrono::milliseconds settle{300};
  // After writing, before leaving the bus (reliable repair of a lost packet).
  std::chrono::milliseconds linger{500};
};

// Errors: kInvalidArgument (a command the table refuses: world_commands.hpp; the message says
// what it needs), kInvalidArgument/kNotFound/kInternal from creating the participant, kTimeout
// when no physics server matched within match_timeout.
Status SendWorldCommand(const bus::ParticipantConfig& config, const WorldCommandInput& command,
                        const SendOptions& options);

}  // namespace swarmbox::physics
