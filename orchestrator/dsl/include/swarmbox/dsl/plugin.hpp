// Plugin: one container of a trial (a Module). Build creates it (not started), Run starts it and
// waits for its readiness pattern, Stop stops it, collects its logs and artifacts and removes it.
//
//   trial.Add<Plugin>("physics", ContainerSpec::Image(img, {"swarmbox-physics", "--seed", "42"}), 1)
//       .On(sim, "10.77.3.2")
//       .ReadyOn("event=ready", Duration::Seconds(60))
//       .Collect("/out/truth.csv");
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "swarmbox/dsl/component.hpp"
#include "swarmbox/dsl/duration.hpp"

namespace swarmbox::dsl {

struct Attachment {
  std::string network;   // the Network component's id in the same trial ("sim", "mesh")
  std::string ipv4;      // fixed address inside that network's subnet
  std::vector<std::string> aliases;  // DNS names on that network
};

// A tmpfs: writable, in memory (counted in the container's memory limit), empty at every start.
struct TmpfsMount {
  std::string path;         // absolute path in the container
  std::int64_t size_mib = 0;  // 0 = the engine's default (half the host's memory)
};

// A host file copied into the container before it starts (Docker's archive endpoint, so it works
// on remote engines too; `swarmbox compose` bind-mounts it instead).
struct InputFile {
  std::string host_path;       // absolute path on the machine running swarmbox
  std::string container_path;  // absolute path in the container
};

struct ContainerSpec {
  std::string name;   // Docker name, unique per host: "<trial>-<run>-<component>"
  std::string image;  // "swarmbox/agent:3f2a..."
  std::vector<std::string> argv;  // the full command line (entrypoint + arguments); no shell
  // argv replaces only the image's CMD and keeps its ENTRYPOINT (a user's image, whose program
  // SwarmBox does not know); empty argv then keeps the image's CMD too.
  bool argv_is_cmd = false;
  std::map<std::string, std::string> env;
  std::map<std::string, std::string> labels;
  std::vector<Attachment> networks;
  // Share another plugin's network namespace: that plugin's id in the same trial ("" = own
  // namespace on `networks`). Then `networks` and `hostname` must be empty (Docker refuses them);
  // the other plugin must be running first (lower run priority).
  std::string network_of;
  // No network at all (Docker's NetworkMode "none"); `networks` must then be empty.
  bool no_network = false;
  // TCP ports published on the host (the physics server's live view, `swarmbox run --view`).
  struct Port {
    int container_port = 0;
    std::string host_ip;
    int host_port = 0;
  };
  std::vector<Port> ports;
  std::vector<std::string> cap_add;   // e.g. "NET_ADMIN" (the fault sidecar only)
  std::vector<std::string> cap_drop;  // e.g. "ALL"
  // Least privilege: SecurityOpt no-new-privileges; a read-only root filesystem, where the
  // container writes only into `volumes` and `tmpfs`; memory and pids limits (0 = unlimited).
  bool no_new_privileges = false;
  bool read_only_rootfs = false;
  // Anonymous volumes (absolute paths): kept across a restart of the container, readable after
  // it stopped (artifacts), removed with it. With read_only_rootfs, `inputs` and `scratch_dirs`
  // must lie under one of them (they are copied in before the start).
  std::vector<std::string> volumes;
  std::vector<TmpfsMount> tmpfs;
  std::int64_t memory_mib = 0;
  std::int64_t pids_limit = 0;
  std::string user;      // "" = the image's
  std::string hostname;  // "" = Docker's
  std::string ready_pattern;  // a regex on the log; "" = ready once started
  Duration ready_timeout = Duration::Seconds(60);
  std::vector<InputFile> inputs;           // copied in before start
  std::vector<std::string> scratch_dirs;  // created empty and world-writable before start (/out)
  std::vector<std::string> artifacts;  // absolute paths in the container collected on Stop
  // Where the artifacts go, relative to the trial folder ("" = the trial folder itself), e.g.
  // "components/recorder". Files keep their names; a folder's files keep their relative paths.
  std::string artifacts_dir;
  int stop_timeout_s = 10;             // SIGTERM, then SIGKILL after this

  // ContainerSpec::Image("swarmbox/physics:1", {"swarmbox-physics", "--seed", "42"})
  static ContainerSpec Image(std::string image, std::vector<std::string> argv = {}) {
    ContainerSpec c;
    c.image = std::move(image);
    c.argv = std::move(argv);
    return c;
  }
};

class Plugin : public Module {
 public:
  Plugin(std::string id, ContainerSpec spec, int run_priority = 2);

  const ContainerSpec& spec() const { return spec_; }
  ContainerSpec& mutable_spec() { return spec_; }

  // Fluent setters for the C++ DSL.
  Plugin& On(const Network& network, std::string ipv4, std::vector<std::string> aliases = {});
  Plugin& ReadyOn(std::string pattern, Duration timeout = Duration::Seconds(60));
  Plugin& Collect(std::string path_in_container);
  Plugin& Env(std::string key, std::string value);
  Plugin& Priority(int run_priority);

 protected:
  Verdict DoBuild(Engine& engine) override;
  Verdict DoRun(Engine& engine) override;
  Verdict DoStop(Engine& engine) override;

 private:
  ContainerSpec spec_;
};

}  // namespace swarmbox::dsl
