// HttpTransport: one HTTP/1.1 exchange with a Docker engine, whole or streamed.
//
// The seam between DockerClient (which knows the Engine API) and the wire. The real one is
// CurlTransport: libcurl to an EngineEndpoint (engine_endpoint.hpp), a unix socket
// (CURLOPT_UNIX_SOCKET_PATH: the local engine, or an ssh-forwarded remote daemon's socket) or TCP,
// plain or TLS ($DOCKER_HOST=tcp://...). UnixSocketTransport is the unix-socket one by path.
// Tests replace it with recorded exchanges.
//
//   UnixSocketTransport t("/var/run/docker.sock");
//   HttpRequest req{.method = "GET", .target = "/_ping"};
//   Result<HttpResponse> r = t.Send(req, nullptr, nullptr);
//
// Contract: Send() returns an Error only when no complete HTTP answer arrived (engine absent:
// kUnavailable; timed out: kTimeout; connection broke: kIo; token fired: kCancelled). Every HTTP
// status, 4xx and 5xx included, is a successful Result carrying that status: mapping statuses to
// errors is the caller's job, done once in DockerClient. Errors have where = "<METHOD> <target>
// (<endpoint>)".
//
// Thread-safety: Send() may be called concurrently from any number of threads (one libcurl easy
// handle per call).
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/cancel_token.hpp"
#include "swarmbox/docker/engine_endpoint.hpp"

namespace swarmbox::docker {

struct HttpRequest {
  std::string method = "GET";
  std::string target;        // path and query, e.g. "/v1.41/containers/json?all=1"
  std::string content_type;  // "" = no body header ("application/json", "application/x-tar")
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  // extra request headers
  // Whole-exchange limit; 0 = none (log follow, events, wait, build).
  std::chrono::milliseconds timeout{0};
};

struct HttpResponse {
  int status = 0;
  std::map<std::string, std::string> headers;  // names lower-cased; last value wins
  // The body; for streamed 2xx responses it is empty (the chunks went to the callback).
  std::string body;

  bool success() const { return status >= 200 && status < 300; }
  // The header value, or "" when absent. `name` must be lower case.
  std::string Header(std::string_view name) const;
};

// Receives the body of a 2xx response in arrival order, chunk by chunk, as soon as bytes arrive.
using BodyChunkFn = std::function<void(std::string_view chunk)>;

class HttpTransport {
 public:
  virtual ~HttpTransport() = default;
  // `on_chunk` null: the whole body is collected into the response. Non-null: a 2xx body is
  // streamed to it instead (other statuses are still collected, they carry Docker's message).
  // `cancel` may be null.
  virtual Result<HttpResponse> Send(const HttpRequest& request, const BodyChunkFn& on_chunk,
                                    CancelToken* cancel) = 0;
  // Where this transport goes, for error messages: "unix:///var/run/docker.sock".
  virtual std::string endpoint() const = 0;
};

// libcurl to an engine: a unix socket, or TCP with TLS (CURLOPT_CAINFO / SSLCERT / SSLKEY from
// the endpoint's files) or without. Large bodies are sent with an empty `Expect:` header (libcurl
// would otherwise wait a second for "100 Continue"). Cancellation wakes the transfer immediately
// (curl_multi_wakeup), not at the next progress tick.
class CurlTransport : public HttpTransport {
 public:
  explicit CurlTransport(EngineEndpoint engine,
                         std::chrono::milliseconds connect_timeout = std::chrono::seconds(5));
  Result<HttpResponse> Send(const HttpRequest& request, const BodyChunkFn& on_chunk,
                            CancelToken* cancel) override;
  std::string endpoint() const override { return engine_.ToString(); }
  const EngineEndpoint& engine() const { return engine_; }

 private:
  EngineEndpoint engine_;
  std::string base_url_;
  std::chrono::milliseconds connect_timeout_;
};

// CurlTransport on a unix socket.
class UnixSocketTransport final : public CurlTransport {
 public:
  explicit UnixSocketTransport(std::string socket_path,
                               std::chrono::milliseconds connect_timeout = std::chrono::seconds(5))
      : CurlTransport(UnixEngine(std::move(socket_path)), connect_timeout) {}
  const std::string& socket_path() const { return engine().socket_path; }
};

}  // namespace swarmbox::docker
