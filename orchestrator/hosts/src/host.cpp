#include "swarmbox/hosts/host.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

extern char** environ;

namespace swarmbox::hosts {

namespace fs = std::filesystem;

namespace {

std::string SafeFileName(std::string s) {
  for (char& c : s) {
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
          c == '-' || c == '_')) {
      c = '_';
    }
  }
  return s;
}

bool IsSocket(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISSOCK(st.st_mode);
}

// Starts ssh with stdin and stdout on /dev/null and stderr into `log`, in its own process group.
Result<pid_t> SpawnSsh(const std::vector<std::string>& args, const std::string& log) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);

  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  // Own process group: a Ctrl-C on the terminal reaches swarmbox, which then tears down in order
  // (the tunnel must outlive the trials' teardown).
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, argv[0], &fa, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) {
    return Error(rc == ENOENT ? ErrorCode::kNotFound : ErrorCode::kIo,
                 std::string("cannot start ssh: ") + std::strerror(rc) +
                     (rc == ENOENT ? " (install openssh-client)" : ""),
                 "ssh");
  }
  return pid;
}

}  // namespace

Result<std::unique_ptr<SshTunnel>> SshTunnel::Open(const HostSpec& spec, const std::string& workdir,
                                                   std::chrono::milliseconds timeout) {
  std::error_code ec;
  fs::create_directories(workdir, ec);
  if (ec) return Error(ErrorCode::kIo, "cannot create " + workdir + ": " + ec.message());
  const std::string base = (fs::path(workdir) / SafeFileName(spec.name())).string();
  const std::string sock = base + ".sock";
  const std::string log = base + ".ssh.log";
  // A unix socket path is limited to 108 bytes (sun_path).
  if (sock.size() >= 100) {
    return Error(ErrorCode::kInvalidArgument,
                 "the forwarded socket path is too long for a unix socket: " + sock);
  }
  fs::remove(sock, ec);
  auto pid = SpawnSsh(SshTunnelArgv(spec, sock, workdir), log);
  if (!pid) return pid.error();
  std::unique_ptr<SshTunnel> tunnel(new SshTunnel(*pid, sock, log));
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    if (IsSocket(sock)) return tunnel;
    int status = 0;
    if (::waitpid(*pid, &status, WNOHANG) == *pid) {
      tunnel->reaped_ = true;
      const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      return ClassifySshFailure(spec, tunnel->StderrText(), code);
    }
    if (std::chrono::steady_clock::now() > deadline) {
      Error e = ClassifySshFailure(spec, tunnel->StderrText(), -1);
      return Error(ErrorCode::kTimeout,
                   "no forwarded socket after " + std::to_string(timeout.count()) + " ms: " +
                       e.message(),
                   "ssh");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

SshTunnel::~SshTunnel() {
  if (!reaped_) {
    ::kill(pid_, SIGTERM);
    for (int i = 0; i < 50; ++i) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        reaped_ = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    if (!reaped_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  std::error_code ec;
  fs::remove(local_socket_, ec);
}

bool SshTunnel::alive() {
  if (reaped_) return false;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) reaped_ = true;
  return !reaped_;
}

std::string SshTunnel::StderrText() const {
  std::ifstream in(log_file_);
  std::ostringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  return text;
}

Status Host::Check() {
  auto ping = client_->Ping();
  if (ping) return Ok{};
  if (tunnel_) {
    const bool alive = tunnel_->alive();
    Error e = ClassifySshFailure(spec_, tunnel_->StderrText(), alive ? -1 : 255);
    return Error(ErrorCode::kUnavailable,
                 name() + " does not answer (" + ping.error().message() + ")" +
                     (alive ? "" : ", the ssh tunnel exited") + ": " + e.message(),
                 "host " + name());
  }
  return ping.error().Context("host " + name());
}

Result<std::unique_ptr<Host>> ConnectHost(const HostSpec& spec, const std::string& workdir) {
  std::unique_ptr<Host> host(new Host());
  host->spec_ = spec;
  docker::DockerClientOptions options;
  if (spec.kind == HostSpec::Kind::kLocal) {
    options.socket_path = spec.socket;
  } else {
    auto tunnel = SshTunnel::Open(spec, workdir, std::chrono::seconds(20));
    if (!tunnel) return tunnel.error();
    host->tunnel_ = std::move(*tunnel);
    options.socket_path = host->tunnel_->local_socket();
  }
  // The local engine without a socket given: $DOCKER_HOST (unix:// or tcp://), as the docker CLI
  // reads it.
  auto client = [&]() -> Result<std::unique_ptr<docker::DockerClient>> {
    if (spec.kind != HostSpec::Kind::kLocal || !spec.socket.empty()) {
      return docker::DockerClient::Connect(options);
    }
    auto engine = docker::EngineEndpointFromEnvironment();
    if (!engine) return engine.error();
    return docker::DockerClient::Connect(*engine, options);
  }();
  if (!client) {
    if (host->tunnel_) {
      // Give ssh a moment to print why the channel was refused.
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      Error e = ClassifySshFailure(spec, host->tunnel_->StderrText(), -1);
      return Error(e.code(), "connecting to the Docker engine of " + spec.name() + ": " +
                                 client.error().message() + "; " + e.message(),
                   "host " + spec.name());
    }
    return client.error().Context("connecting to the local Docker engine");
  }
  host->client_ = std::move(*client);
  return host;
}

}  // namespace swarmbox::hosts
