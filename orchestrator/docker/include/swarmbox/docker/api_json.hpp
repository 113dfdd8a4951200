// The pure Engine API mapping: request bodies and queries built from DockerApi's value types, and
// Docker's JSON answers parsed back into them. No I/O, so it is tested against recorded engine
// responses (tests/orchestrator/docker/data/). JSON goes through swarmbox::yaml (libyaml).
//
//   std::string body = CreateContainerBody(spec, /*all_networks=*/false);
//   Result<ContainerInfo> info = ParseContainerInspect(response.body);
//
// Parse errors are kProtocol without `where`; the client adds the endpoint.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"

namespace swarmbox::docker {

// API versions as comparable numbers: "1.41" -> {1, 41}. Malformed text is kProtocol.
struct ApiVersion {
  int major = 0;
  int minor = 0;
  auto operator<=>(const ApiVersion&) const = default;
  std::string ToString() const { return std::to_string(major) + "." + std::to_string(minor); }
};
Result<ApiVersion> ParseApiVersion(std::string_view text);

// --- queries --------------------------------------------------------------------------------------

// Percent-encodes everything but RFC 3986 unreserved characters.
std::string UrlEncode(std::string_view text);
// The `filters` query value: {"label":["k=v","k"], <extra>...} as JSON (not yet URL-encoded).
std::string FiltersJson(const LabelSelector& labels,
                        const std::map<std::string, std::vector<std::string>>& extra = {});
// "?t=...&labels=...&dockerfile=..." for POST /build.
std::string BuildQuery(const BuildRequest& request);

// --- request bodies (JSON) ------------------------------------------------------------------------

// POST /containers/create. all_networks: put every network into NetworkingConfig (API >= 1.44);
// otherwise only the first (the caller connects the rest before starting).
std::string CreateContainerBody(const ContainerSpec& spec, bool all_networks);
std::string CreateNetworkBody(const NetworkSpec& spec);
std::string ConnectNetworkBody(const EndpointSpec& endpoint, std::string_view container_id);
std::string DisconnectNetworkBody(std::string_view container_id, bool force);
std::string ExecCreateBody(const ExecSpec& spec);
std::string ExecStartBody(bool tty);

// --- responses ------------------------------------------------------------------------------------

Result<EngineVersion> ParseVersion(std::string_view body);
Result<ImageInfo> ParseImageInspect(std::string_view body);
Result<std::vector<ImageInfo>> ParseImageList(std::string_view body);
Result<NetworkInfo> ParseNetwork(std::string_view body);  // one inspect or one list item
Result<std::vector<NetworkInfo>> ParseNetworkList(std::string_view body);
Result<ContainerInfo> ParseContainerInspect(std::string_view body);
Result<std::vector<ContainerSummary>> ParseContainerList(std::string_view body);
Result<std::string> ParseIdResponse(std::string_view body);  // {"Id": "..."}
// POST /containers/{id}/wait: the exit code; {"Error": {"Message": m}} with a message is an error.
Result<std::int64_t> ParseWaitResponse(std::string_view body);
Result<ExecState> ParseExecInspect(std::string_view body);
Result<Event> ParseEvent(std::string_view line);

// One line of POST /build's JSON stream.
struct BuildMessage {
  std::string stream;  // build output text ("Step 1/3 : FROM scratch\n"), may be empty
  std::string status;  // progress status text
  std::string error;   // errorDetail.message (or error): the build failed
  std::string aux_id;  // aux.ID: the built image id
};
Result<BuildMessage> ParseBuildLine(std::string_view line);

// Docker's error text from an error response body ({"message": "..."}), or the trimmed body
// itself when it is not JSON; "" for an empty body.
std::string ErrorMessageFromBody(std::string_view body);

// The one place HTTP statuses become Errors (STYLE.md 10). `creating`: the call creates
// something, so 409 means kAlreadyExists (otherwise 409 is a state conflict, kInvalidArgument).
// Message: "HTTP <status>: <Docker's message>".
Error HttpStatusError(int status, std::string_view body, std::string where, bool creating);

}  // namespace swarmbox::docker
