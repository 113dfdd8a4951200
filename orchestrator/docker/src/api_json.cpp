#include "swarmbox/docker/api_json.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <ctime>
#include <type_traits>
#include <utility>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::docker {
namespace {

using yaml::Node;

// --- building ---------------------------------------------------------------------------------------

Node Str(std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); }
Node Int(std::int64_t v) { return Node::Scalar(std::to_string(v)); }
Node Bool(bool b) { return Node::Scalar(b ? "true" : "false"); }

Node StrList(const std::vector<std::string>& items) {
  Node list = Node::Sequence();
  for (const std::string& s : items) list.Append(Str(s));
  return list;
}

Node StrMap(const std::map<std::string, std::string>& items) {
  Node map = Node::Mapping();
  for (const auto& [k, v] : items) map.Set(k, Str(v));
  return map;
}

Node EnvList(const std::map<std::string, std::string>& env) {
  Node list = Node::Sequence();
  for (const auto& [k, v] : env) list.Append(Str(k + "=" + v));
  return list;
}

Node EndpointConfig(const EndpointSpec& endpoint) {
  Node config = Node::Mapping();
  if (!endpoint.ipv4_address.empty()) {
    Node ipam = Node::Mapping();
    ipam.Set("IPv4Address", Str(endpoint.ipv4_address));
    config.Set("IPAMConfig", std::move(ipam));
  }
  if (!endpoint.aliases.empty()) config.Set("Aliases", StrList(endpoint.aliases));
  return config;
}

std::string_view MountTypeName(Mount::Type type) {
  switch (type) {
    case Mount::Type::kBind:
      return "bind";
    case Mount::Type::kVolume:
      return "volume";
    case Mount::Type::kTmpfs:
      return "tmpfs";
  }
  return "bind";
}

// --- reading ----------------------------------------------------------------------------------------

Result<Node> ParseJson(std::string_view body, std::string_view what) {
  auto doc = yaml::Parse(body, what);
  if (!doc) {
    return Error(ErrorCode::kProtocol,
                 "unparseable JSON in " + std::string(what) + ": " + doc.error().ToString());
  }
  return std::move(*doc);
}

Error Malformed(std::string_view what, std::string_view expected) {
  return Error(ErrorCode::kProtocol,
               std::string(what) + ": expected " + std::string(expected) + " in Docker's answer");
}

const Node* Child(const Node& node, std::string_view key) {
  if (!node.is_mapping()) return nullptr;
  const Node* child = node.Find(key);
  if (child == nullptr || child->is_null() || yaml::IsNullScalar(*child)) return nullptr;
  return child;
}

std::string GetStr(const Node& node, std::string_view key) {
  const Node* child = Child(node, key);
  return child != nullptr && child->is_scalar() ? child->scalar() : std::string();
}

std::int64_t GetInt(const Node& node, std::string_view key) {
  const Node* child = Child(node, key);
  if (child == nullptr || !child->is_scalar()) return 0;
  auto v = child->AsInt();
  return v ? *v : 0;
}

bool GetBool(const Node& node, std::string_view key) {
  const Node* child = Child(node, key);
  if (child == nullptr || !child->is_scalar()) return false;
  auto v = yaml::ScalarAsBool(child->scalar());
  return v.value_or(false);
}

std::map<std::string, std::string> GetStrMap(const Node& node, std::string_view key) {
  std::map<std::string, std::string> out;
  const Node* child = Child(node, key);
  if (child == nullptr || !child->is_mapping()) return out;
  for (const auto& [k, v] : child->entries()) {
    out[k.scalar()] = v.is_scalar() ? v.scalar() : std::string();
  }
  return out;
}

std::vector<std::string> GetStrList(const Node& node, std::string_view key) {
  std::vector<std::string> out;
  const Node* child = Child(node, key);
  if (child == nullptr || !child->is_sequence()) return out;
  for (const Node& item : child->items()) {
    if (item.is_scalar()) out.push_back(item.scalar());
  }
  return out;
}

std::string StripSlash(std::string name) {
  if (!name.empty() && name.front() == '/') name.erase(0, 1);
  return name;
}

// Docker's answer as a JSON object; kProtocol naming `what` when it is not one.
Result<Node> ParseJsonObject(std::string_view body, std::string_view what) {
  auto doc = ParseJson(body, what);
  if (!doc) return doc.error();
  if (!doc->is_mapping()) return Malformed(what, "an object");
  return doc;
}

// Docker's answer as a JSON array; kProtocol naming `what` when it is not one.
Result<Node> ParseJsonArray(std::string_view body, std::string_view what) {
  auto doc = ParseJson(body, what);
  if (!doc) return doc.error();
  if (!doc->is_sequence()) return Malformed(what, "an array");
  return doc;
}

// A list answer (ParseJsonArray), each item read by `from_node` (a Node -> the item's struct).
template <class FromNode>
auto ParseListOf(std::string_view body, std::string_view what, FromNode from_node)
    -> Result<std::vector<std::invoke_result_t<FromNode, const Node&>>> {
  auto doc = ParseJsonArray(body, what);
  if (!doc) return doc.error();
  std::vector<std::invoke_result_t<FromNode, const Node&>> out;
  for (const Node& item : doc->items()) out.push_back(from_node(item));
  return out;
}

// An inspect answer: an object with a non-empty "Id".
Result<Node> ParseJsonWithId(std::string_view body, std::string_view what) {
  auto doc = ParseJson(body, what);
  if (!doc) return doc.error();
  if (!doc->is_mapping() || GetStr(*doc, "Id").empty()) return Malformed(what, "Id");
  return doc;
}

// An object in which `key` is present and not null.
Result<Node> ParseJsonWithKey(std::string_view body, std::string_view what, std::string_view key) {
  auto doc = ParseJson(body, what);
  if (!doc) return doc.error();
  if (!doc->is_mapping() || Child(*doc, key) == nullptr) return Malformed(what, key);
  return doc;
}

// "2026-11-21T13:05:29.123456789Z" -> unix seconds (UTC; fractional part dropped). 0 if unparsable.
std::int64_t ParseRfc3339(const std::string& text) {
  std::tm tm{};
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  if (std::sscanf(text.c_str(), "%d-%d-%dT%d:%d:%d", &year, &month, &day, &hour, &minute,
                  &second) != 6) {
    return 0;
  }
  tm.tm_year = year - 1900;
  tm.tm_mon = month - 1;
  tm.tm_mday = day;
  tm.tm_hour = hour;
  tm.tm_min = minute;
  tm.tm_sec = second;
  return static_cast<std::int64_t>(timegm(&tm));
}

ImageInfo ImageFromNode(const Node& n, bool from_list) {
  ImageInfo info;
  info.id = GetStr(n, "Id");
  info.repo_tags = GetStrList(n, "RepoTags");
  info.size_bytes = GetInt(n, "Size");
  if (from_list) {
    info.created_unix_s = GetInt(n, "Created");
    info.labels = GetStrMap(n, "Labels");
  } else {
    info.created_unix_s = ParseRfc3339(GetStr(n, "Created"));
    if (const Node* config = Child(n, "Config")) info.labels = GetStrMap(*config, "Labels");
  }
  return info;
}

NetworkInfo NetworkFromNode(const Node& n) {
  NetworkInfo info;
  info.id = GetStr(n, "Id");
  info.name = GetStr(n, "Name");
  info.driver = GetStr(n, "Driver");
  info.internal = GetBool(n, "Internal");
  info.labels = GetStrMap(n, "Labels");
  if (const Node* ipam = Child(n, "IPAM")) {
    if (const Node* config = Child(*ipam, "Config"); config != nullptr && config->is_sequence() &&
                                                     !config->items().empty()) {
      info.subnet = GetStr(config->items()[0], "Subnet");
      info.gateway = GetStr(config->items()[0], "Gateway");
    }
  }
  if (const Node* containers = Child(n, "Containers"); containers != nullptr &&
                                                       containers->is_mapping()) {
    for (const auto& [k, v] : containers->entries()) info.container_ids.push_back(k.scalar());
  }
  return info;
}

}  // namespace

Result<ApiVersion> ParseApiVersion(std::string_view text) {
  ApiVersion v;
  const std::size_t dot = text.find('.');
  if (dot == std::string_view::npos) {
    return Error(ErrorCode::kProtocol, "malformed API version '" + std::string(text) + "'");
  }
  const char* begin = text.data();
  auto r1 = std::from_chars(begin, begin + dot, v.major);
  auto r2 = std::from_chars(begin + dot + 1, begin + text.size(), v.minor);
  if (r1.ec != std::errc() || r1.ptr != begin + dot || r2.ec != std::errc() ||
      r2.ptr != begin + text.size()) {
    return Error(ErrorCode::kProtocol, "malformed API version '" + std::string(text) + "'");
  }
  return v;
}

std::string UrlEncode(std::string_view text) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string out;
  out.reserve(text.size() * 3);
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' ||
        c == '_' || c == '.' || c == '~') {
      out.push_back(ch);
    } else {
      out.push_back('%');
      out.push_back(kHex[c >> 4]);
      out.push_back(kHex[c & 0x0F]);
    }
  }
  return out;
}

std::string FiltersJson(const LabelSelector& labels,
                        const std::map<std::string, std::vector<std::string>>& extra) {
  Node filters = Node::Mapping();
  if (!labels.equals.empty()) {
    Node list = Node::Sequence();
    for (const auto& [k, v] : labels.equals) list.Append(Str(v.empty() ? k : k + "=" + v));
    filters.Set("label", std::move(list));
  }
  for (const auto& [k, values] : extra) {
    if (!values.empty()) filters.Set(k, StrList(values));
  }
  return yaml::EmitJson(filters);
}

std::string BuildQuery(const BuildRequest& request) {
  std::string q = "?dockerfile=" + UrlEncode(request.dockerfile);
  for (const std::string& tag : request.tags) q += "&t=" + UrlEncode(tag);
  if (!request.labels.empty()) q += "&labels=" + UrlEncode(yaml::EmitJson(StrMap(request.labels)));
  if (!request.build_args.empty()) {
    q += "&buildargs=" + UrlEncode(yaml::EmitJson(StrMap(request.build_args)));
  }
  q += "&rm=1&forcerm=1";
  if (request.no_cache) q += "&nocache=1";
  if (request.pull) q += "&pull=1";
  return q;
}

namespace {

// The container's own settings (Config): image, command, environment, identity, ports exposed.
void SetContainerConfig(const ContainerSpec& spec, Node* body) {
  body->Set("Image", Str(spec.image));
  if (!spec.entrypoint.empty()) body->Set("Entrypoint", StrList(spec.entrypoint));
  if (!spec.cmd.empty()) body->Set("Cmd", StrList(spec.cmd));
  if (!spec.env.empty()) body->Set("Env", EnvList(spec.env));
  if (!spec.user.empty()) body->Set("User", Str(spec.user));
  if (!spec.working_dir.empty()) body->Set("WorkingDir", Str(spec.working_dir));
  if (!spec.hostname.empty()) body->Set("Hostname", Str(spec.hostname));
  body->Set("Labels", StrMap(spec.labels));
  body->Set("Tty", Bool(spec.tty));
  body->Set("OpenStdin", Bool(spec.open_stdin));
  body->Set("AttachStdout", Bool(false));
  body->Set("AttachStderr", Bool(false));
  if (!spec.stop_signal.empty()) body->Set("StopSignal", Str(spec.stop_signal));
  if (spec.stop_timeout_s) body->Set("StopTimeout", Int(*spec.stop_timeout_s));
  if (!spec.ports.empty()) {
    Node exposed = Node::Mapping();
    for (const PortBinding& p : spec.ports) exposed.Set(std::to_string(p.container_port) + "/tcp", Node::Mapping());
    body->Set("ExposedPorts", std::move(exposed));
  }
}

Node MountNode(const Mount& m) {
  Node mount = Node::Mapping();
  mount.Set("Type", Str(MountTypeName(m.type)));
  if (m.type != Mount::Type::kTmpfs) mount.Set("Source", Str(m.source));
  mount.Set("Target", Str(m.target));
  mount.Set("ReadOnly", Bool(m.read_only));
  if (m.type == Mount::Type::kTmpfs && (m.tmpfs_size_bytes > 0 || m.tmpfs_mode > 0)) {
    Node tmpfs = Node::Mapping();
    if (m.tmpfs_size_bytes > 0) tmpfs.Set("SizeBytes", Int(m.tmpfs_size_bytes));
    if (m.tmpfs_mode > 0) tmpfs.Set("Mode", Int(m.tmpfs_mode));
    mount.Set("TmpfsOptions", std::move(tmpfs));
  }
  return mount;
}

Node PortBindingsNode(const std::vector<PortBinding>& ports) {
  Node bindings = Node::Mapping();
  for (const PortBinding& p : ports) {
    Node binding = Node::Mapping();
    binding.Set("HostIp", Str(p.host_ip));
    binding.Set("HostPort", Str(std::to_string(p.host_port)));
    Node list = Node::Sequence();
    list.Append(std::move(binding));
    bindings.Set(std::to_string(p.container_port) + "/tcp", std::move(list));
  }
  return bindings;
}

// HostConfig: mounts, network mode, capabilities, resources, ports, root filesystem.
Node HostConfigNode(const ContainerSpec& spec) {
  Node host = Node::Mapping();
  if (!spec.mounts.empty()) {
    Node mounts = Node::Sequence();
    for (const Mount& m : spec.mounts) mounts.Append(MountNode(m));
    host.Set("Mounts", std::move(mounts));
  }
  std::string network_mode = spec.network_mode;
  if (network_mode.empty() && !spec.networks.empty()) network_mode = spec.networks.front().network;
  if (!network_mode.empty()) host.Set("NetworkMode", Str(network_mode));
  if (!spec.cap_add.empty()) host.Set("CapAdd", StrList(spec.cap_add));
  if (!spec.cap_drop.empty()) host.Set("CapDrop", StrList(spec.cap_drop));
  if (!spec.security_opt.empty()) host.Set("SecurityOpt", StrList(spec.security_opt));
  if (spec.resources.memory_bytes > 0) {
    host.Set("Memory", Int(spec.resources.memory_bytes));
    // A hard limit: no swap on top of it (Docker's default allows as much swap again).
    host.Set("MemorySwap", Int(spec.resources.memory_bytes));
  }
  if (spec.resources.nano_cpus > 0) host.Set("NanoCpus", Int(spec.resources.nano_cpus));
  if (spec.resources.pids_limit > 0) host.Set("PidsLimit", Int(spec.resources.pids_limit));
  if (!spec.resources.cpuset_cpus.empty()) host.Set("CpusetCpus", Str(spec.resources.cpuset_cpus));
  if (!spec.sysctls.empty()) host.Set("Sysctls", StrMap(spec.sysctls));
  if (!spec.extra_hosts.empty()) host.Set("ExtraHosts", StrList(spec.extra_hosts));
  if (!spec.ports.empty()) host.Set("PortBindings", PortBindingsNode(spec.ports));
  host.Set("ReadonlyRootfs", Bool(spec.read_only_rootfs));
  if (spec.init) host.Set("Init", Bool(true));
  host.Set("AutoRemove", Bool(spec.auto_remove));
  return host;
}

}  // namespace

std::string CreateContainerBody(const ContainerSpec& spec, bool all_networks) {
  Node body = Node::Mapping();
  SetContainerConfig(spec, &body);
  body.Set("HostConfig", HostConfigNode(spec));
  if (!spec.networks.empty()) {
    Node endpoints = Node::Mapping();
    const std::size_t n = all_networks ? spec.networks.size() : 1;
    for (std::size_t i = 0; i < n; ++i) {
      endpoints.Set(spec.networks[i].network, EndpointConfig(spec.networks[i]));
    }
    Node networking = Node::Mapping();
    networking.Set("EndpointsConfig", std::move(endpoints));
    body.Set("NetworkingConfig", std::move(networking));
  }
  return yaml::EmitJson(body);
}

std::string CreateNetworkBody(const NetworkSpec& spec) {
  Node body = Node::Mapping();
  body.Set("Name", Str(spec.name));
  body.Set("CheckDuplicate", Bool(true));
  body.Set("Driver", Str(spec.driver));
  body.Set("Internal", Bool(spec.internal));
  body.Set("Attachable", Bool(spec.attachable));
  body.Set("Labels", StrMap(spec.labels));
  if (!spec.options.empty()) body.Set("Options", StrMap(spec.options));
  if (!spec.subnet.empty()) {
    Node config = Node::Mapping();
    config.Set("Subnet", Str(spec.subnet));
    if (!spec.gateway.empty()) config.Set("Gateway", Str(spec.gateway));
    Node configs = Node::Sequence();
    configs.Append(std::move(config));
    Node ipam = Node::Mapping();
    ipam.Set("Driver", Str("default"));
    ipam.Set("Config", std::move(configs));
    body.Set("IPAM", std::move(ipam));
  }
  return yaml::EmitJson(body);
}

std::string ConnectNetworkBody(const EndpointSpec& endpoint, std::string_view container_id) {
  Node body = Node::Mapping();
  body.Set("Container", Str(container_id));
  body.Set("EndpointConfig", EndpointConfig(endpoint));
  return yaml::EmitJson(body);
}

std::string DisconnectNetworkBody(std::string_view container_id, bool force) {
  Node body = Node::Mapping();
  body.Set("Container", Str(container_id));
  body.Set("Force", Bool(force));
  return yaml::EmitJson(body);
}

std::string ExecCreateBody(const ExecSpec& spec) {
  Node body = Node::Mapping();
  body.Set("AttachStdin", Bool(false));
  body.Set("AttachStdout", Bool(true));
  body.Set("AttachStderr", Bool(true));
  body.Set("Tty", Bool(spec.tty));
  body.Set("Cmd", StrList(spec.cmd));
  if (!spec.env.empty()) body.Set("Env", EnvList(spec.env));
  if (!spec.user.empty()) body.Set("User", Str(spec.user));
  if (!spec.working_dir.empty()) body.Set("WorkingDir", Str(spec.working_dir));
  body.Set("Privileged", Bool(spec.privileged));
  return yaml::EmitJson(body);
}

std::string ExecStartBody(bool tty) {
  Node body = Node::Mapping();
  body.Set("Detach", Bool(false));
  body.Set("Tty", Bool(tty));
  return yaml::EmitJson(body);
}

Result<EngineVersion> ParseVersion(std::string_view body) {
  auto doc = ParseJsonObject(body, "GET /version");
  if (!doc) return doc.error();
  EngineVersion v;
  v.version = GetStr(*doc, "Version");
  v.api_version = GetStr(*doc, "ApiVersion");
  v.min_api_version = GetStr(*doc, "MinAPIVersion");
  v.os = GetStr(*doc, "Os");
  v.arch = GetStr(*doc, "Arch");
  v.kernel_version = GetStr(*doc, "KernelVersion");
  if (v.api_version.empty()) return Malformed("GET /version", "ApiVersion");
  return v;
}

Result<ImageInfo> ParseImageInspect(std::string_view body) {
  auto doc = ParseJsonWithId(body, "image inspect");
  if (!doc) return doc.error();
  return ImageFromNode(*doc, /*from_list=*/false);
}

Result<std::vector<ImageInfo>> ParseImageList(std::string_view body) {
  return ParseListOf(body, "image list",
                     [](const Node& item) { return ImageFromNode(item, /*from_list=*/true); });
}

Result<NetworkInfo> ParseNetwork(std::string_view body) {
  auto doc = ParseJsonWithId(body, "network inspect");
  if (!doc) return doc.error();
  return NetworkFromNode(*doc);
}

Result<std::vector<NetworkInfo>> ParseNetworkList(std::string_view body) {
  return ParseListOf(body, "network list", NetworkFromNode);
}

namespace {

ContainerState ContainerStateFromNode(const Node& state) {
  ContainerState out;
  out.status = GetStr(state, "Status");
  out.running = GetBool(state, "Running");
  out.paused = GetBool(state, "Paused");
  out.oom_killed = GetBool(state, "OOMKilled");
  out.pid = static_cast<int>(GetInt(state, "Pid"));
  out.exit_code = GetInt(state, "ExitCode");
  out.error = GetStr(state, "Error");
  out.started_at = GetStr(state, "StartedAt");
  out.finished_at = GetStr(state, "FinishedAt");
  return out;
}

// One entry of HostConfig.Mounts; an unknown type reads as a bind mount.
Mount MountFromNode(const Node& m) {
  Mount mount;
  const std::string type = GetStr(m, "Type");
  mount.type = type == "volume"  ? Mount::Type::kVolume
               : type == "tmpfs" ? Mount::Type::kTmpfs
                                 : Mount::Type::kBind;
  mount.source = GetStr(m, "Source");
  mount.target = GetStr(m, "Target");
  mount.read_only = GetBool(m, "ReadOnly");
  if (const Node* tmpfs = Child(m, "TmpfsOptions")) {
    mount.tmpfs_size_bytes = GetInt(*tmpfs, "SizeBytes");
    mount.tmpfs_mode = static_cast<int>(GetInt(*tmpfs, "Mode"));
  }
  return mount;
}

ContainerHostConfig HostConfigFromNode(const Node& host) {
  ContainerHostConfig hc;
  hc.cap_add = GetStrList(host, "CapAdd");
  hc.cap_drop = GetStrList(host, "CapDrop");
  hc.security_opt = GetStrList(host, "SecurityOpt");
  hc.read_only_rootfs = GetBool(host, "ReadonlyRootfs");
  hc.memory_bytes = GetInt(host, "Memory");
  hc.pids_limit = std::max<std::int64_t>(0, GetInt(host, "PidsLimit"));
  hc.network_mode = GetStr(host, "NetworkMode");
  if (const Node* mounts = Child(host, "Mounts"); mounts != nullptr && mounts->is_sequence()) {
    for (const Node& m : mounts->items()) hc.mounts.push_back(MountFromNode(m));
  }
  return hc;
}

// NetworkSettings.Networks: network name -> the container's address on it.
std::map<std::string, std::string> NetworkIpsFromNode(const Node& settings) {
  std::map<std::string, std::string> ips;
  if (const Node* networks = Child(settings, "Networks"); networks != nullptr && networks->is_mapping()) {
    for (const auto& [name, endpoint] : networks->entries()) {
      ips[name.scalar()] = GetStr(endpoint, "IPAddress");
    }
  }
  return ips;
}

}  // namespace

Result<ContainerInfo> ParseContainerInspect(std::string_view body) {
  auto doc = ParseJsonWithId(body, "container inspect");
  if (!doc) return doc.error();
  ContainerInfo info;
  info.id = GetStr(*doc, "Id");
  info.name = StripSlash(GetStr(*doc, "Name"));
  info.image = GetStr(*doc, "Image");
  if (const Node* state = Child(*doc, "State")) info.state = ContainerStateFromNode(*state);
  if (const Node* config = Child(*doc, "Config")) {
    info.labels = GetStrMap(*config, "Labels");
    info.tty = GetBool(*config, "Tty");
  }
  if (const Node* host = Child(*doc, "HostConfig")) info.host_config = HostConfigFromNode(*host);
  if (const Node* settings = Child(*doc, "NetworkSettings")) info.network_ips = NetworkIpsFromNode(*settings);
  return info;
}

Result<std::vector<ContainerSummary>> ParseContainerList(std::string_view body) {
  return ParseListOf(body, "container list", [](const Node& item) {
    ContainerSummary s;
    s.id = GetStr(item, "Id");
    for (std::string& name : GetStrList(item, "Names")) s.names.push_back(StripSlash(name));
    s.image = GetStr(item, "Image");
    s.state = GetStr(item, "State");
    s.status = GetStr(item, "Status");
    s.labels = GetStrMap(item, "Labels");
    return s;
  });
}

Result<std::string> ParseIdResponse(std::string_view body) {
  auto doc = ParseJson(body, "create response");
  if (!doc) return doc.error();
  std::string id = GetStr(*doc, "Id");
  if (id.empty()) return Malformed("create response", "Id");
  return id;
}

Result<std::int64_t> ParseWaitResponse(std::string_view body) {
  auto doc = ParseJsonWithKey(body, "wait response", "StatusCode");
  if (!doc) return doc.error();
  if (const Node* error = Child(*doc, "Error")) {
    std::string message = GetStr(*error, "Message");
    if (!message.empty()) return Error(ErrorCode::kInternal, "wait failed: " + message);
  }
  return GetInt(*doc, "StatusCode");
}

Result<ExecState> ParseExecInspect(std::string_view body) {
  auto doc = ParseJsonWithKey(body, "exec inspect", "Running");
  if (!doc) return doc.error();
  ExecState state;
  state.running = GetBool(*doc, "Running");
  state.pid = static_cast<int>(GetInt(*doc, "Pid"));
  if (const Node* process = Child(*doc, "ProcessConfig")) state.tty = GetBool(*process, "tty");
  if (Child(*doc, "ExitCode") != nullptr && !state.running) {
    state.exit_code = GetInt(*doc, "ExitCode");
  }
  return state;
}

Result<Event> ParseEvent(std::string_view line) {
  auto doc = ParseJsonObject(line, "event");
  if (!doc) return doc.error();
  Event e;
  e.type = GetStr(*doc, "Type");
  e.action = GetStr(*doc, "Action");
  if (const Node* actor = Child(*doc, "Actor")) {
    e.actor_id = GetStr(*actor, "ID");
    e.attributes = GetStrMap(*actor, "Attributes");
  }
  if (e.actor_id.empty()) e.actor_id = GetStr(*doc, "id");
  e.time_unix_ns = GetInt(*doc, "timeNano");
  if (e.time_unix_ns == 0) e.time_unix_ns = GetInt(*doc, "time") * 1000000000;
  if (e.type.empty() || e.action.empty()) return Malformed("event", "Type and Action");
  return e;
}

Result<BuildMessage> ParseBuildLine(std::string_view line) {
  auto doc = ParseJsonObject(line, "build output");
  if (!doc) return doc.error();
  BuildMessage m;
  m.stream = GetStr(*doc, "stream");
  m.status = GetStr(*doc, "status");
  if (const Node* detail = Child(*doc, "errorDetail")) m.error = GetStr(*detail, "message");
  if (m.error.empty()) m.error = GetStr(*doc, "error");
  if (const Node* aux = Child(*doc, "aux")) m.aux_id = GetStr(*aux, "ID");
  return m;
}

std::string ErrorMessageFromBody(std::string_view body) {
  std::string_view trimmed = body;
  while (!trimmed.empty() && (trimmed.back() == '\n' || trimmed.back() == '\r' ||
                              trimmed.back() == ' ')) {
    trimmed.remove_suffix(1);
  }
  if (trimmed.empty()) return {};
  if (trimmed.front() == '{') {
    if (auto doc = yaml::Parse(trimmed, "error"); doc && doc->is_mapping()) {
      std::string message = GetStr(*doc, "message");
      if (!message.empty()) return message;
    }
  }
  return std::string(trimmed);
}

Error HttpStatusError(int status, std::string_view body, std::string where, bool creating) {
  ErrorCode code = ErrorCode::kProtocol;
  if (status == 404) {
    code = ErrorCode::kNotFound;
  } else if (status == 409) {
    code = creating ? ErrorCode::kAlreadyExists : ErrorCode::kInvalidArgument;
  } else if (status >= 400 && status < 500) {
    code = ErrorCode::kInvalidArgument;
  } else if (status == 502 || status == 503 || status == 504) {
    code = ErrorCode::kUnavailable;
  } else if (status >= 500) {
    code = ErrorCode::kInternal;
  }
  std::string message = ErrorMessageFromBody(body);
  if (message.empty()) message = "(no message)";
  return Error(code, "HTTP " + std::to_string(status) + ": " + message, std::move(where));
}

}  // namespace swarmbox::docker
