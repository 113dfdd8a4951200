// EngineEndpoint: where the Docker engine is, read from $DOCKER_HOST, $DOCKER_TLS_VERIFY,
// $DOCKER_TLS and $DOCKER_CERT_PATH the way the docker CLI reads them.
//
//   DOCKER_HOST unset or ""          unix:///var/run/docker.sock
//   unix:///run/user/1000/docker.sock that socket
//   tcp://10.0.0.5:2375              plain HTTP (port default 2375, 2376 with TLS)
//   tcp://... + DOCKER_TLS_VERIFY=1  HTTPS, the engine's certificate checked against
//                                    $DOCKER_CERT_PATH/ca.pem (default ~/.docker; the system's
//                                    CAs when there is no ca.pem), the client's own
//                                    cert.pem/key.pem presented when they exist
//   tcp://... + DOCKER_TLS=1         HTTPS without checking the engine's certificate
//   ssh://user@host                  refused with what to do instead (swarmbox experiment
//                                    --hosts ssh://..., or a forwarded socket + unix://)
//   anything else                    refused (kInvalidArgument): never a silent fall-back to
//                                    the local socket
//
//   auto engine = EngineEndpointFromEnvironment();
//   if (!engine) return engine.error();   // "DOCKER_HOST=...: ..." (bad input: exit 2)
//   DockerClientOptions o; o.engine = *engine;
//
// ParseEngineEndpoint is pure (the environment passed in); EngineEndpointFromEnvironment reads
// the process environment and checks that the certificate files named exist.
#pragma once

#include <string>

#include "swarmbox/common/result.hpp"

namespace swarmbox::docker {

inline constexpr char kDefaultDockerSocket[] = "/var/run/docker.sock";

struct EngineEndpoint {
  enum class Kind { kUnix, kTcp };
  Kind kind = Kind::kUnix;
  std::string socket_path = kDefaultDockerSocket;  // kUnix
  std::string host;                                // kTcp: name or address ("::1" without brackets)
  int port = 0;                                    // kTcp
  bool tls = false;                                // kTcp: HTTPS
  bool tls_verify = false;                         // check the engine's certificate with ca_file
  std::string ca_file;                             // "" = none (tls without verify)
  std::string cert_file;                           // client certificate; "" = none
  std::string key_file;

  // "unix:///var/run/docker.sock", "tcp://127.0.0.1:2375", "tcp://h:2376 (TLS)": for messages.
  std::string ToString() const;
  // The URL prefix of requests: "http://docker" (unix), "http://h:2375", "https://[::1]:2376".
  std::string BaseUrl() const;
};

EngineEndpoint UnixEngine(std::string socket_path);

// The environment the docker CLI reads; "" = unset.
struct DockerEnvironment {
  std::string docker_host;
  std::string tls_verify;  // DOCKER_TLS_VERIFY: any non-empty value turns TLS with verification on
  std::string tls;         // DOCKER_TLS: any non-empty value turns TLS on
  std::string cert_path;   // DOCKER_CERT_PATH ("" = $HOME/.docker)
  std::string home;        // HOME
};

// Errors: kInvalidArgument with where = "DOCKER_HOST" and the value in the message.
Result<EngineEndpoint> ParseEngineEndpoint(const DockerEnvironment& env);

DockerEnvironment DockerEnvironmentFromProcess();

// ParseEngineEndpoint(DockerEnvironmentFromProcess()), then, as the docker CLI does, the
// certificate files that do not exist are dropped (cert.pem without key.pem, or the reverse, is
// an error).
Result<EngineEndpoint> EngineEndpointFromEnvironment();

}  // namespace swarmbox::docker
