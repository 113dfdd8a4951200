#include "command_sender.hpp"

#include <thread>

#include "swarmbox/bus/topics.hpp"
#include "world_commands.hpp"

namespace swarmbox::physics {

Status SendWorldCommand(const bus::ParticipantConfig& config, const WorldCommandInput& command,
                        const SendOptions& options) {
  if (Status s = CheckWorldCommand(command.command, !command.target.empty(), command.args); !s) {
    return Error(ErrorCode::kInvalidArgument, "world command " + command.command + ": " + s.error().message());
  }
  auto participant = bus::Participant::Create(config);
  if (!participant) return participant.error().Context("joining the sim bus");
  auto writer = (*participant)->CreatePublisher<bus::WorldCommand>(bus::kWorldCommandTopic, bus::Qos::kLockstep);
  if (!writer) return writer.error().Context("creating the world-command writer");
  if (Status s = (*writer)->WaitForSubscribers(1, options.match_timeout); !s) {
    return Error(ErrorCode::kTimeout,
                 "no physics server matched on " + std::string(bus::kWorldCommandTopic) + " (domain " +
                     std::to_string(config.domain_id) + ", interface " + config.interface + ", " +
                     config.backend + ") within " + std::to_string(options.match_timeout.count()) + " ms");
  }
  std::this_thread::sleep_for(options.settle);
  bus::WorldCommand msg;
  msg.seq = 1;
  msg.sim_time_ns = 0;  // the server applies it at its current step
  msg.target = command.target;
  msg.command = command.command;
  msg.args = command.args;
  if (Status s = (*writer)->Publish(msg); !s) return s.error().Context("publishing the world command");
  std::this_thread::sleep_for(options.linger);
  return Ok{};
}

}  // namespace swarmbox::physics
