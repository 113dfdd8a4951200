// DockerClient: the real DockerApi, the Docker Engine API over an HttpTransport (normally libcurl on
// a unix socket: the local engine, or a remote daemon's socket forwarded over ssh).
//
//   auto client = DockerClient::Connect({.socket_path = DefaultSocketPath()});
//   if (!client) return client.error();     // kUnavailable: "no Docker engine answers at ..."
//   DockerApi& api = **client;
//
// Version negotiation: Connect() reads the engine's API version from /_ping (falling back to
// /version) and speaks min(engine, kMaxApiVersion); engines older than kMinApiVersion are refused.
// Below API 1.44 a container's second and later networks are connected with /networks/{id}/connect
// before CreateContainer returns (several networks at create time needs 1.44).
//
// Thread-safety: all methods may be called concurrently; the negotiated version is fixed at
// Connect() and every call runs its own HTTP exchange.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "swarmbox/docker/api_json.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/docker/engine_endpoint.hpp"
#include "swarmbox/docker/http_transport.hpp"

namespace swarmbox::docker {

// $DOCKER_HOST when it is unix://PATH, else /var/run/docker.sock. Only for callers that need a
// socket path; the engine a user means is EngineEndpointFromEnvironment() (tcp:// too).
std::string DefaultSocketPath();

struct DockerClientOptions {
  // The engine (engine_endpoint.hpp): set it from EngineEndpointFromEnvironment() to honour
  // $DOCKER_HOST. Unset: the unix socket below.
  std::optional<EngineEndpoint> engine = {};  // (initialised: designated initialisers may leave it out)
  std::string socket_path = "/var/run/docker.sock";
  std::chrono::milliseconds connect_timeout{5000};
  // Limit for ordinary calls (not for streams, wait, build, exec start). Stop/restart add their
  // grace period to it.
  std::chrono::milliseconds request_timeout{60000};
};

class DockerClient final : public DockerApi {
 public:
  static constexpr ApiVersion kMinApiVersion{1, 40};
  static constexpr ApiVersion kMaxApiVersion{1, 44};

  // Connects to options.engine (else the unix socket) and negotiates the API version.
  static Result<std::unique_ptr<DockerClient>> Connect(const DockerClientOptions& options);
  // Same over any transport (recorded exchanges in tests).
  static Result<std::unique_ptr<DockerClient>> Connect(std::unique_ptr<HttpTransport> transport,
                                                       std::chrono::milliseconds request_timeout);

  Result<std::string> Ping() override;
  Result<EngineVersion> Version() override;
  std::string api_version() const override { return version_.ToString(); }

  Result<BuildResult> BuildImage(const BuildRequest& request, const BuildProgressFn& progress,
                                 CancelToken* cancel) override;
  Result<ImageInfo> InspectImage(std::string_view reference) override;
  Result<std::vector<ImageInfo>> ListImages(const LabelSelector& selector) override;
  Status RemoveImage(std::string_view reference, bool force) override;

  Result<std::string> CreateNetwork(const NetworkSpec& spec) override;
  Result<NetworkInfo> InspectNetwork(std::string_view id) override;
  Result<std::vector<NetworkInfo>> ListNetworks(const LabelSelector& selector) override;
  Status ConnectNetwork(const EndpointSpec& endpoint, std::string_view container_id) override;
  Status DisconnectNetwork(std::string_view network_id, std::string_view container_id,
                           bool force) override;
  Status RemoveNetwork(std::string_view id) override;

  Result<std::string> CreateContainer(const ContainerSpec& spec) override;
  Result<ContainerInfo> InspectContainer(std::string_view id) override;
  Result<std::vector<ContainerSummary>> ListContainers(const LabelSelector& selector,
                                                       bool all) override;
  Status StartContainer(std::string_view id) override;
  Status StopContainer(std::string_view id, int timeout_s) override;
  Status RestartContainer(std::string_view id, int timeout_s) override;
  Status KillContainer(std::string_view id, std::string_view signal) override;
  Status PauseContainer(std::string_view id) override;
  Status UnpauseContainer(std::string_view id) override;
  Result<std::int64_t> WaitContainer(std::string_view id, WaitCondition condition,
                                     CancelToken* cancel) override;
  Status RemoveContainer(std::string_view id, bool force, bool remove_volumes) override;

  Status FollowLogs(std::string_view id, const LogOptions& options, const LogLineFn& on_line,
                    CancelToken* cancel) override;

  Result<std::string> CreateExec(std::string_view container_id, const ExecSpec& spec) override;
  Status StartExec(std::string_view exec_id, const LogLineFn& on_line,
                   CancelToken* cancel) override;
  Result<ExecState> InspectExec(std::string_view exec_id) override;

  Status PutArchive(std::string_view container_id, std::string_view dest_dir,
                    std::string_view tar) override;
  Result<std::string> GetArchive(std::string_view container_id, std::string_view path) override;

  Status StreamEvents(const EventFilter& filter, const EventFn& on_event,
                      CancelToken* cancel) override;

  const HttpTransport& transport() const { return *transport_; }

 private:
  struct Call;  // one request's description, see docker_client.cpp

  DockerClient(std::unique_ptr<HttpTransport> transport, std::chrono::milliseconds request_timeout)
      : transport_(std::move(transport)), request_timeout_(request_timeout) {}
  Status Negotiate();
  Result<HttpResponse> Do(const Call& call);
  Status DoStatus(const Call& call);
  // Do(), then `parse` (body -> Result<T>) with parse errors located at the request.
  template <typename Parse>
  auto DoParsed(const Call& call, Parse parse) -> decltype(parse(std::string()));
  // Streams a log-like body (logs, exec output) through a LogDemuxer.
  Status StreamLines(Call call, bool tty, const LogLineFn& on_line);

  std::unique_ptr<HttpTransport> transport_;
  std::chrono::milliseconds request_timeout_;
  ApiVersion version_{1, 41};
};

}  // namespace swarmbox::docker
