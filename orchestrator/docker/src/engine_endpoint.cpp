#include "swarmbox/docker/engine_endpoint.hpp"

#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <string_view>

namespace swarmbox::docker {

namespace {

Error Bad(const std::string& value, const std::string& why) {
  return Error(ErrorCode::kInvalidArgument, why, "DOCKER_HOST=" + value);
}

// "host:port", "host", "[::1]:port", "[::1]" -> host, port (0 = none given).
Result<std::pair<std::string, int>> SplitHostPort(std::string_view authority, const std::string& value) {
  std::string host;
  std::string_view rest;
  if (!authority.empty() && authority.front() == '[') {
    const std::size_t close = authority.find(']');
    if (close == std::string_view::npos) return Bad(value, "unclosed '[' in the address");
    host = std::string(authority.substr(1, close - 1));
    rest = authority.substr(close + 1);
    if (!rest.empty() && rest.front() != ':') return Bad(value, "expected ':PORT' after ']'");
  } else {
    const std::size_t colon = authority.find(':');
    host = std::string(authority.substr(0, colon));
    rest = colon == std::string_view::npos ? std::string_view() : authority.substr(colon);
  }
  if (host.empty()) return Bad(value, "no host in the address (expected tcp://HOST:PORT)");
  int port = 0;
  if (!rest.empty()) {
    const std::string_view digits = rest.substr(1);
    const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), port);
    if (digits.empty() || r.ec != std::errc() || r.ptr != digits.data() + digits.size() || port < 1 ||
        port > 65535) {
      return Bad(value, "the port '" + std::string(digits) + "' is not a number in 1..65535");
    }
  }
  return std::make_pair(host, port);
}

}  // namespace

std::string EngineEndpoint::ToString() const {
  if (kind == Kind::kUnix) return "unix://" + socket_path;
  const bool v6 = host.find(':') != std::string::npos;
  return "tcp://" + (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port) +
         (tls ? (tls_verify ? " (TLS)" : " (TLS, engine certificate not checked)") : "");
}

std::string EngineEndpoint::BaseUrl() const {
  if (kind == Kind::kUnix) return "http://docker";
  const bool v6 = host.find(':') != std::string::npos;
  return std::string(tls ? "https://" : "http://") + (v6 ? "[" + host + "]" : host) + ":" +
         std::to_string(port);
}

EngineEndpoint UnixEngine(std::string socket_path) {
  EngineEndpoint e;
  e.socket_path = std::move(socket_path);
  return e;
}

namespace {

// Docker's ports for the engine API: plain HTTP and TLS.
constexpr int kDefaultTcpPort = 2375;
constexpr int kDefaultTlsPort = 2376;

// TLS settings from DOCKER_TLS_VERIFY / DOCKER_TLS / DOCKER_CERT_PATH (or ~/.docker), as the
// docker CLI reads them.
Status SetTlsFiles(const DockerEnvironment& env, EngineEndpoint& e) {
  e.tls_verify = !env.tls_verify.empty();
  e.tls = e.tls_verify || !env.tls.empty();
  if (!e.tls) return Ok{};
  const std::string dir = !env.cert_path.empty() ? env.cert_path
                          : !env.home.empty()    ? env.home + "/.docker"
                                                 : std::string();
  if (dir.empty()) {
    return Bad(env.docker_host,
               "TLS is on but neither DOCKER_CERT_PATH nor HOME says where the certificates are");
  }
  if (e.tls_verify) e.ca_file = dir + "/ca.pem";
  e.cert_file = dir + "/cert.pem";
  e.key_file = dir + "/key.pem";
  return Ok{};
}

// The part of DOCKER_HOST after "tcp://": HOST[:PORT][/].
Result<EngineEndpoint> ParseTcpEngine(std::string_view rest, const DockerEnvironment& env) {
  const std::string& value = env.docker_host;
  std::string_view authority = rest;
  const std::size_t slash = authority.find('/');
  if (slash != std::string_view::npos) {
    if (authority.substr(slash) != "/") {
      return Bad(value, "a path after the address is not supported (expected tcp://HOST:PORT)");
    }
    authority = authority.substr(0, slash);
  }
  auto hp = SplitHostPort(authority, value);
  if (!hp) return hp.error();
  EngineEndpoint e;
  e.kind = EngineEndpoint::Kind::kTcp;
  e.host = hp->first;
  if (Status tls = SetTlsFiles(env, e); !tls) return tls.error();
  e.port = hp->second != 0 ? hp->second : (e.tls ? kDefaultTlsPort : kDefaultTcpPort);
  return e;
}

}  // namespace

Result<EngineEndpoint> ParseEngineEndpoint(const DockerEnvironment& env) {
  const std::string& value = env.docker_host;
  if (value.empty()) return UnixEngine(kDefaultDockerSocket);
  const std::size_t sep = value.find("://");
  if (sep == std::string::npos) {
    return Bad(value, "expected unix://PATH or tcp://HOST:PORT (the scheme is missing)");
  }
  const std::string scheme = value.substr(0, sep);
  const std::string_view rest = std::string_view(value).substr(sep + 3);
  if (scheme == "unix") {
    if (rest.empty()) return UnixEngine(kDefaultDockerSocket);  // as the docker CLI
    if (rest.front() != '/') return Bad(value, "the socket path must be absolute (unix:///path)");
    return UnixEngine(std::string(rest));
  }
  if (scheme == "tcp") return ParseTcpEngine(rest, env);
  if (scheme == "ssh") {
    return Bad(value,
               "ssh:// engines are not opened by `swarmbox run/images/gc`; use `swarmbox experiment "
               "--hosts " + value + "` (it forwards the engine's socket over ssh), or forward it "
               "yourself: `ssh -nNT -L /tmp/docker.sock:/var/run/docker.sock " + std::string(rest) +
               "` and DOCKER_HOST=unix:///tmp/docker.sock");
  }
  return Bad(value, "unknown scheme '" + scheme + "' (SwarmBox speaks unix:// and tcp://)");
}

DockerEnvironment DockerEnvironmentFromProcess() {
  auto get = [](const char* name) {
    const char* v = std::getenv(name);
    return v == nullptr ? std::string() : std::string(v);
  };
  return {get("DOCKER_HOST"), get("DOCKER_TLS_VERIFY"), get("DOCKER_TLS"), get("DOCKER_CERT_PATH"),
          get("HOME")};
}

Result<EngineEndpoint> EngineEndpointFromEnvironment() {
  auto e = ParseEngineEndpoint(DockerEnvironmentFromProcess());
  if (!e || !e->tls) return e;
  std::error_code ec;
  for (std::string* file : {&e->ca_file, &e->cert_file, &e->key_file}) {
    if (!file->empty() && !std::filesystem::exists(*file, ec)) file->clear();
  }
  if (e->cert_file.empty() != e->key_file.empty()) {
    return Error(ErrorCode::kInvalidArgument,
                 "DOCKER_CERT_PATH: " + std::string(e->cert_file.empty() ? "key.pem" : "cert.pem") +
                     " is there but not " + (e->cert_file.empty() ? "cert.pem" : "key.pem"),
                 "DOCKER_CERT_PATH");
  }
  return e;
}

}  // namespace swarmbox::docker
