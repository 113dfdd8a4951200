#include "swarmbox/bus/participant.hpp"

#include <thread>

#include "detail/backends.hpp"
#include "detail/net_interface.hpp"

namespace swarmbox::bus {

const std::vector<std::string>& AvailableBackends() {
  static const std::vector<std::string> kBackends = {"cyclonedds", "fastdds"};
  return kBackends;
}

Result<std::unique_ptr<Participant>> Participant::Create(const ParticipantConfig& config) {
  const bool cyclone = config.backend == "cyclonedds";
  const bool fastdds = config.backend == "fastdds";
  if (!cyclone && !fastdds) {
    return Error(ErrorCode::kInvalidArgument,
                 "unknown bus backend '" + config.backend +
                     "': accepted backends are 'cyclonedds' (default) and 'fastdds'");
  }
  if (config.domain_id < 0 || config.domain_id > kMaxDomainId) {
    return Error(ErrorCode::kInvalidArgument,
                 "DDS domain id " + std::to_string(config.domain_id) +
                     " is out of range: accepted domain ids are 0 to " +
                     std::to_string(kMaxDomainId) + " (RTPS ports overflow above)");
  }
  if (config.interface.empty()) {
    return Error(ErrorCode::kInvalidArgument,
                 "no network interface given: name the interface to bind to, e.g. 'lo' or 'eth0'");
  }
  auto address = detail::ResolveInterfaceIpv4(config.interface);
  if (!address) return std::move(address).error().Context("creating bus participant");
  auto impl = cyclone ? detail::CreateCycloneBackend(config, *address)
                      : detail::CreateFastddsBackend(config, *address);
  if (!impl) return std::move(impl).error().Context("creating bus participant");
  return std::unique_ptr<Participant>(
      new Participant(config, std::move(*address), std::move(*impl)));
}

Participant::Participant(ParticipantConfig config, std::string address,
                         std::unique_ptr<detail::ParticipantBackend> impl)
    : config_(std::move(config)), address_(std::move(address)), impl_(std::move(impl)) {}

Participant::~Participant() = default;

Result<std::unique_ptr<detail::WriterBackend>> Participant::CreateWriter(MessageType type,
                                                                         std::string_view topic,
                                                                         Qos qos) {
  SWARMBOX_TRY(ValidateTopicName(topic));
  return impl_->CreateWriter(type, std::string(topic), qos);
}

Result<std::unique_ptr<detail::ReaderBackend>> Participant::CreateReader(
    MessageType type, std::string_view topic, Qos qos, detail::SampleCallback callback) {
  SWARMBOX_TRY(ValidateTopicName(topic));
  return impl_->CreateReader(type, std::string(topic), qos, std::move(callback));
}

namespace detail {

Status WaitForMatched(const std::function<int()>& matched, int count,
                      std::chrono::milliseconds timeout, std::string_view what,
                      std::string_view topic) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int now = matched();
  while (now < count) {
    if (std::chrono::steady_clock::now() >= deadline) {
      return Error(ErrorCode::kTimeout,
                   "only " + std::to_string(now) + " of " + std::to_string(count) + " " +
                       std::string(what) + "s matched on topic '" + std::string(topic) +
                       "' after " + std::to_string(timeout.count()) + " ms");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    now = matched();
  }
  return Ok{};
}

}  // namespace detail
}  // namespace swarmbox::bus
