// A connected host of the pool: the Docker API of the local engine, or of a remote engine through
// an ssh tunnel that forwards its unix socket (I/O: spawns ssh, owns its process).
//
//   auto host = ConnectHost(*ParseHostSpec("ssh://root@10.250.0.2?slots=2"), "/tmp/work");
//   if (!host) return host.error();   // "ssh authentication to root@10.250.0.2 was refused ..."
//   docker::DockerApi& api = (*host)->api();
//
// The tunnel is one `ssh -N -L <workdir>/<host>.sock:<remote socket>` process (argv array, see
// host_spec.hpp) started here and killed (SIGTERM, then SIGKILL) when the host is destroyed; its
// stderr goes to <workdir>/<host>.ssh.log and is what the error messages quote.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <memory>
#include <string>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/hosts/host_spec.hpp"

namespace swarmbox::hosts {

// One `ssh -N -L` process.
class SshTunnel {
 public:
  // Starts ssh and waits (up to `timeout`) until the local socket exists; on failure the ssh
  // process is gone and the error is ClassifySshFailure of its stderr.
  static Result<std::unique_ptr<SshTunnel>> Open(const HostSpec& spec, const std::string& workdir,
                                                 std::chrono::milliseconds timeout);
  ~SshTunnel();
  SshTunnel(const SshTunnel&) = delete;
  SshTunnel& operator=(const SshTunnel&) = delete;

  const std::string& local_socket() const { return local_socket_; }
  pid_t pid() const { return pid_; }
  bool alive();
  std::string StderrText() const;  // what ssh printed so far

 private:
  SshTunnel(pid_t pid, std::string local_socket, std::string log_file)
      : pid_(pid), local_socket_(std::move(local_socket)), log_file_(std::move(log_file)) {}
  pid_t pid_;
  std::string local_socket_;
  std::string log_file_;
  bool reaped_ = false;
};

class Host {
 public:
  const HostSpec& spec() const { return spec_; }
  std::string name() const { return spec_.name(); }
  int slots() const { return spec_.slots; }
  docker::DockerApi& api() { return *client_; }
  // Whether the engine answers now (Ping), with a host-level explanation when not (the tunnel's
  // stderr for ssh hosts).
  Status Check();

 private:
  friend Result<std::unique_ptr<Host>> ConnectHost(const HostSpec&, const std::string&);
  HostSpec spec_;
  std::unique_ptr<SshTunnel> tunnel_;  // null for local
  std::unique_ptr<docker::DockerClient> client_;
};

// Connects (opening the tunnel for ssh) and checks that the engine answers. `workdir` holds the
// forwarded sockets and ssh logs (created if missing).
Result<std::unique_ptr<Host>> ConnectHost(const HostSpec& spec, const std::string& workdir);

}  // namespace swarmbox::hosts
