// DockerApi: the orchestrator's one door to a Docker engine (STYLE.md 3).
//
// Everything the DSL, the runner, `swarmbox images` and `swarmbox gc` do to Docker goes through
// this pure interface. The real implementation is DockerClient (docker_client.hpp: the Engine API
// over a unix socket on libcurl); tests write fakes against it.
//
//   std::unique_ptr<DockerApi> api = ...;             // DockerClient::Connect({}) or a fake
//   ContainerSpec spec;
//   spec.name = "t1-drone_1"; spec.image = tag; spec.user = "1000:1000";
//   spec.labels = SwarmboxLabels(run_id, trial_id, "drone_1");
//   spec.networks = {EndpointSpec{sim_id, "10.77.1.10", {}}, EndpointSpec{mesh_id, "10.77.2.10", {}}};
//   auto id = api->CreateContainer(spec);             // all networks attached on return
//   if (!id) return id.error().Context("creating drone_1");
//   SWARMBOX_TRY(api->StartContainer(*id));
//   CancelToken stop;
//   api->FollowLogs(*id, {}, [&](const LogLine& l) { if (Matches(l.text)) stop.Cancel(); }, &stop);
//
// Errors (every method): a Result error carries `where` = the endpoint ("POST /v1.41/containers/
// create" plus the socket) and Docker's own message. Codes: kNotFound (404: no such container,
// network, image), kAlreadyExists (409 on create: the name is taken), kInvalidArgument (400, and 409
// on state changes such as "container is not running"), kUnavailable (no engine at the socket, 503),
// kTimeout, kIo (socket broke mid-call), kProtocol (unparseable answer), kInternal (500),
// kCancelled (a CancelToken fired).
//
// Thread-safety: implementations must allow concurrent calls from several threads (the runner
// follows the logs of every container at once). Callbacks run on the calling thread, one at a time
// per call; a callback must not block for long (it stalls that stream only).
//
// Ids: wherever a method takes `id`, Docker accepts a full id, a unique id prefix or the name.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/cancel_token.hpp"

namespace swarmbox::docker {

using Labels = std::map<std::string, std::string>;

// Label keys of the labelling contract (ARCHITECTURE.md "Labels").
inline constexpr std::string_view kLabelRun = "swarmbox.run";
inline constexpr std::string_view kLabelTrial = "swarmbox.trial";
inline constexpr std::string_view kLabelComponent = "swarmbox.component";

// {swarmbox.run=run_id, swarmbox.trial=trial_id, swarmbox.component=component}.
Labels SwarmboxLabels(std::string_view run_id, std::string_view trial_id,
                      std::string_view component);

// A label selector as Docker filters understand it: key present (value empty) or key=value. All
// entries must match (AND).
struct LabelSelector {
  std::map<std::string, std::string> equals;  // "key" -> "value"; value "" means "key present"
};

// --- engine ---------------------------------------------------------------------------------------

struct EngineVersion {
  std::string version;          // engine version, e.g. "20.10.24+dfsg1"
  std::string api_version;      // highest API the engine speaks, e.g. "1.41"
  std::string min_api_version;  // lowest API the engine speaks, e.g. "1.12"
  std::string os;               // "linux"
  std::string arch;             // "amd64"
  std::string kernel_version;
};

// --- images ---------------------------------------------------------------------------------------

struct BuildRequest {
  std::string context_tar;            // an uncompressed tar holding the Dockerfile and its files
  std::string dockerfile = "Dockerfile";  // path of the Dockerfile inside the context
  std::vector<std::string> tags;      // "repo:tag"; at least one
  Labels labels;                      // set on the image
  std::map<std::string, std::string> build_args;
  bool no_cache = false;
  bool pull = false;                  // never true on registry-free hosts
};

// One line of build output as the engine streamed it ("Step 1/4 : FROM scratch"), newline removed.
using BuildProgressFn = std::function<void(std::string_view line)>;

struct BuildResult {
  std::string image_id;  // "sha256:..."
};

struct ImageInfo {
  std::string id;                       // "sha256:..."
  std::vector<std::string> repo_tags;   // "swarmbox/physics:3f2a..."
  std::int64_t size_bytes = 0;
  std::int64_t created_unix_s = 0;
  Labels labels;
};

// --- networks -------------------------------------------------------------------------------------

struct NetworkSpec {
  std::string name;
  std::string driver = "bridge";
  std::string subnet;    // CIDR, e.g. "10.77.1.0/24"; required for fixed container addresses
  std::string gateway;   // optional, e.g. "10.77.1.1"
  bool internal = false; // no route to the outside
  bool attachable = true;
  Labels labels;
  std::map<std::string, std::string> options;  // driver options, e.g. com.docker.network.driver.mtu
};

struct NetworkInfo {
  std::string id;
  std::string name;
  std::string driver;
  std::string subnet;   // first IPAM config, "" when none
  std::string gateway;
  bool internal = false;
  Labels labels;
  std::vector<std::string> container_ids;  // attached containers (inspect only; empty from lists)
};

// How a container sits on one network.
struct EndpointSpec {
  std::string network;                // network id or name
  std::string ipv4_address;           // fixed address inside the network's subnet, "" = any
  std::vector<std::string> aliases;   // DNS names on this network
};

// --- containers -----------------------------------------------------------------------------------

struct Mount {
  enum class Type { kBind, kVolume, kTmpfs };
  Type type = Type::kBind;
  std::string source;  // host path (bind) or volume name; unused for tmpfs
  std::string target;  // path in the container
  bool read_only = false;
  std::int64_t tmpfs_size_bytes = 0;  // tmpfs only; 0 = engine default
  // tmpfs only: its mode (e.g. 01777); 0 = the engine's. Docker 20.10 copies the mode of a
  // directory the image already has at `target` over it (tmpcopyup), whatever this says.
  int tmpfs_mode = 0;
};

struct ResourceLimits {
  std::int64_t memory_bytes = 0;  // 0 = unlimited; also MemorySwap: no swap beyond it
  std::int64_t nano_cpus = 0;     // 1e9 = one CPU; 0 = unlimited
  std::int64_t pids_limit = 0;    // 0 = unlimited
  std::string cpuset_cpus;        // "0-1"; "" = any
};

// A container's TCP port published on the host (ExposedPorts and HostConfig.PortBindings).
struct PortBinding {
  int container_port = 0;  // e.g. 8765
  std::string host_ip;     // e.g. "127.0.0.1"; "" = every address
  int host_port = 0;       // e.g. 8765
  bool operator==(const PortBinding&) const = default;
};

struct ContainerSpec {
  std::string name;                      // "" lets Docker choose
  std::string image;                     // reference, e.g. "swarmbox/agent:3f2a..."
  std::vector<std::string> entrypoint;   // empty = the image's
  std::vector<std::string> cmd;          // argv after the entrypoint; empty = the image's
  std::map<std::string, std::string> env;
  std::string user;                      // "1000:1000"; "" = the image's USER
  std::string working_dir;
  std::string hostname;
  Labels labels;
  std::vector<Mount> mounts;
  // Networks with fixed addresses. The implementation attaches ALL of them before
  // CreateContainer returns: the first at create time and, on engines below API 1.44, the others
  // with /networks/{id}/connect (the container is not started).
  std::vector<EndpointSpec> networks;
  // HostConfig.NetworkMode: "" (the first of `networks`, or Docker's default bridge when none),
  // "none", or "container:<id>" to share another container's network namespace (fault sidecar;
  // `networks` must then be empty).
  std::string network_mode;
  std::vector<std::string> cap_add;      // e.g. "NET_ADMIN"
  std::vector<std::string> cap_drop;     // e.g. "ALL"
  std::vector<std::string> security_opt; // HostConfig.SecurityOpt, e.g. "no-new-privileges"
  ResourceLimits resources;
  std::map<std::string, std::string> sysctls;
  std::vector<std::string> extra_hosts;  // "name:ip"
  std::vector<PortBinding> ports;        // TCP ports published on the host
  bool tty = false;                      // logs are then raw, not multiplexed
  bool open_stdin = false;
  bool read_only_rootfs = false;
  bool init = false;                     // run docker-init as pid 1
  bool auto_remove = false;              // discouraged: logs vanish on exit (issue facts)
  std::string stop_signal;               // "" = SIGTERM
  std::optional<int> stop_timeout_s;
};

struct ContainerState {
  std::string status;  // "created", "running", "paused", "restarting", "removing", "exited", "dead"
  bool running = false;
  bool paused = false;
  bool oom_killed = false;
  int pid = 0;
  std::int64_t exit_code = 0;
  std::string error;
  std::string started_at;   // RFC 3339 as Docker writes it
  std::string finished_at;
};

// What a container was created with (inspect's HostConfig), as far as the orchestrator sets it.
struct ContainerHostConfig {
  std::vector<std::string> cap_add;
  std::vector<std::string> cap_drop;
  std::vector<std::string> security_opt;
  bool read_only_rootfs = false;
  std::int64_t memory_bytes = 0;  // 0 = unlimited
  std::int64_t pids_limit = 0;    // 0 (or Docker's -1/null) = unlimited
  std::vector<Mount> mounts;      // HostConfig.Mounts (type, target, read-only, tmpfs size/mode)
  std::string network_mode;
};

struct ContainerInfo {
  std::string id;
  std::string name;   // without Docker's leading '/'
  std::string image;  // the image id the container was created from
  ContainerState state;
  Labels labels;
  std::map<std::string, std::string> network_ips;  // network name -> IPv4 address
  bool tty = false;  // created with a TTY: its logs are raw, not multiplexed
  ContainerHostConfig host_config;
};

struct ContainerSummary {
  std::string id;
  std::vector<std::string> names;  // without leading '/'
  std::string image;
  std::string state;   // "running", "exited", ...
  std::string status;  // human text, "Up 3 seconds"
  Labels labels;
};

enum class WaitCondition { kNotRunning, kNextExit, kRemoved };

// --- logs -----------------------------------------------------------------------------------------

enum class StreamKind { kStdin = 0, kStdout = 1, kStderr = 2 };

struct LogLine {
  StreamKind stream = StreamKind::kStdout;
  std::string text;  // one line, without its '\n' (a final unterminated line is delivered at end)
};
using LogLineFn = std::function<void(const LogLine& line)>;

struct LogOptions {
  bool follow = true;       // keep streaming until the container stops (or the token fires)
  bool stdout = true;
  bool stderr = true;
  bool timestamps = false;  // prefix each line with Docker's RFC 3339 time
  std::int64_t since_unix_s = 0;
  std::optional<int> tail;  // last N lines only; nullopt = all
};

// --- exec -----------------------------------------------------------------------------------------

struct ExecSpec {
  std::vector<std::string> cmd;  // argv, no shell
  std::map<std::string, std::string> env;
  std::string user;
  std::string working_dir;
  bool tty = false;
  bool privileged = false;
};

struct ExecState {
  bool running = false;
  std::optional<std::int64_t> exit_code;  // set once the process has ended
  int pid = 0;
  bool tty = false;
};

// --- events ---------------------------------------------------------------------------------------

struct EventFilter {
  LabelSelector labels;
  std::vector<std::string> types;    // "container", "network", "image"; empty = all
  std::vector<std::string> actions;  // "start", "die", "oom", ...; empty = all
  std::int64_t since_unix_s = 0;     // 0 = from now
};

struct Event {
  std::string type;     // "container"
  std::string action;   // "die"
  std::string actor_id;
  std::map<std::string, std::string> attributes;  // labels and e.g. exitCode, name, image
  std::int64_t time_unix_ns = 0;
};
using EventFn = std::function<void(const Event& event)>;

// --- the interface --------------------------------------------------------------------------------

class DockerApi {
 public:
  virtual ~DockerApi() = default;

  // Engine.
  virtual Result<std::string> Ping() = 0;  // the engine's API version from /_ping's header
  virtual Result<EngineVersion> Version() = 0;
  // The API version this client speaks to the engine, e.g. "1.41" (negotiated at connect).
  virtual std::string api_version() const = 0;

  // Images. BuildImage streams the engine's output lines to `progress` (may be empty); a build
  // that fails inside the stream (errorDetail) is an Error with Docker's message. `cancel` may be
  // null.
  virtual Result<BuildResult> BuildImage(const BuildRequest& request,
                                         const BuildProgressFn& progress,
                                         CancelToken* cancel) = 0;
  virtual Result<ImageInfo> InspectImage(std::string_view reference) = 0;  // kNotFound if absent
  virtual Result<std::vector<ImageInfo>> ListImages(const LabelSelector& selector) = 0;
  virtual Status RemoveImage(std::string_view reference, bool force) = 0;

  // Networks.
  virtual Result<std::string> CreateNetwork(const NetworkSpec& spec) = 0;  // the network id
  virtual Result<NetworkInfo> InspectNetwork(std::string_view id) = 0;
  virtual Result<std::vector<NetworkInfo>> ListNetworks(const LabelSelector& selector) = 0;
  virtual Status ConnectNetwork(const EndpointSpec& endpoint, std::string_view container_id) = 0;
  virtual Status DisconnectNetwork(std::string_view network_id, std::string_view container_id,
                                   bool force) = 0;
  virtual Status RemoveNetwork(std::string_view id) = 0;

  // Containers. Start/Stop of a container already in that state succeed (Docker's 304).
  virtual Result<std::string> CreateContainer(const ContainerSpec& spec) = 0;  // the container id
  virtual Result<ContainerInfo> InspectContainer(std::string_view id) = 0;
  // all = also stopped containers.
  virtual Result<std::vector<ContainerSummary>> ListContainers(const LabelSelector& selector,
                                                               bool all) = 0;
  virtual Status StartContainer(std::string_view id) = 0;
  // SIGTERM (or the stop signal), then SIGKILL after timeout_s.
  virtual Status StopContainer(std::string_view id, int timeout_s) = 0;
  virtual Status RestartContainer(std::string_view id, int timeout_s) = 0;
  virtual Status KillContainer(std::string_view id, std::string_view signal) = 0;  // "SIGKILL"
  virtual Status PauseContainer(std::string_view id) = 0;
  virtual Status UnpauseContainer(std::string_view id) = 0;
  // Blocks until the condition holds; returns the exit code. `cancel` may be null.
  virtual Result<std::int64_t> WaitContainer(std::string_view id, WaitCondition condition,
                                             CancelToken* cancel) = 0;
  virtual Status RemoveContainer(std::string_view id, bool force, bool remove_volumes) = 0;

  // Logs as a stream: complete lines are delivered as they arrive (multiplexed or TTY raw, as the
  // container was created). With options.follow it returns Ok when the container's output ends
  // (it stopped), kCancelled when `cancel` fired. `cancel` may be null. Call it after
  // StartContainer: nothing is lost (the stream starts at the container's first line), whereas a
  // never-started container would end the stream at once; that case is kInvalidArgument.
  virtual Status FollowLogs(std::string_view id, const LogOptions& options,
                            const LogLineFn& on_line, CancelToken* cancel) = 0;

  // Exec: create, then start attached (output lines to `on_line`, may be empty; returns when the
  // process ends), then InspectExec for the exit code.
  virtual Result<std::string> CreateExec(std::string_view container_id, const ExecSpec& spec) = 0;
  virtual Status StartExec(std::string_view exec_id, const LogLineFn& on_line,
                           CancelToken* cancel) = 0;
  virtual Result<ExecState> InspectExec(std::string_view exec_id) = 0;

  // Archive: put an uncompressed tar, extracted under `dest_dir` (which must exist), and get a
  // path (file or directory) as a tar whose entries are named from the path's last component.
  virtual Status PutArchive(std::string_view container_id, std::string_view dest_dir,
                            std::string_view tar) = 0;
  virtual Result<std::string> GetArchive(std::string_view container_id,
                                         std::string_view path) = 0;

  // Events, streamed until `cancel` fires (then kCancelled) or the engine closes the stream.
  virtual Status StreamEvents(const EventFilter& filter, const EventFn& on_event,
                              CancelToken* cancel) = 0;
};

}  // namespace swarmbox::docker
