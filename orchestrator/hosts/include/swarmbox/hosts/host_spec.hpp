// Host specs of an experiment's pool (`swarmbox experiment --hosts ...`), and the ssh command
// line that forwards a remote Docker socket (pure: parsing, argv, error classification).
//
//   local                       the local engine ($DOCKER_HOST or /var/run/docker.sock), 1 slot
//   local?slots=2               2 trials in parallel
//   ssh://user@host[:port][?slots=N&socket=/path/docker.sock&identity=KEY&known_hosts=FILE]
//
// An ssh host is reached through one long-lived tunnel:
//   ssh -N -o BatchMode=yes -o StrictHostKeyChecking=yes [-o UserKnownHostsFile=FILE]
//       [-i KEY -o IdentitiesOnly=yes] -o ExitOnForwardFailure=yes -o StreamLocalBindUnlink=yes
//       -o ControlMaster=auto -o ControlPath=<dir>/cm-%C -o ControlPersist=no
//       -o ServerAliveInterval=5 -o ServerAliveCountMax=3 -o ConnectTimeout=10
//       -p PORT -L <local.sock>:<socket> user@host
// Host keys are always checked (no trust on first use): the host must be in known_hosts.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::hosts {

struct HostSpec {
  enum class Kind { kLocal, kSsh };
  Kind kind = Kind::kLocal;
  std::string text;  // as given
  int slots = 1;
  // kLocal: the socket ("" = docker::DefaultSocketPath()); kSsh: the remote socket path.
  std::string socket;
  std::string user;  // kSsh; "" = ssh's default
  std::string host;  // kSsh
  int port = 22;
  std::string identity;     // private key file; "" = ssh's defaults
  std::string known_hosts;  // "" = ssh's default (~/.ssh/known_hosts)

  // "local", or "user@host:port": the `host` column of results.csv and result.json.
  std::string name() const;
};

inline constexpr std::string_view kDefaultRemoteSocket = "/var/run/docker.sock";

// kInvalidArgument with the problem and the accepted forms.
Result<HostSpec> ParseHostSpec(std::string_view text);
// Several specs, also comma-separated in one argument ("local,ssh://a@b").
Result<std::vector<HostSpec>> ParseHostSpecs(const std::vector<std::string>& texts);

// The argv of the tunnel (see above).
std::vector<std::string> SshTunnelArgv(const HostSpec& spec, const std::string& local_socket,
                                       const std::string& control_dir);

// Turns what ssh printed on stderr (and its exit code, -1 = still running) into an error that
// says what to do: host key unknown or changed, authentication refused, host unreachable, the
// remote Docker socket missing or not permitted. kUnavailable for network trouble (retry may
// help), kInvalidArgument for configuration (keys, known_hosts, permissions).
Error ClassifySshFailure(const HostSpec& spec, std::string_view ssh_stderr, int exit_code);

}  // namespace swarmbox::hosts
