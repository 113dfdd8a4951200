#include "swarmbox/runner/compose_export.hpp"

#include <algorithm>
#include <filesystem>
#include <map>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::runner {

namespace {

using yaml::Node;

Node Str(std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); }

Node StrList(const std::vector<std::string>& items) {
  Node seq = Node::Sequence();
  for (const auto& s : items) seq.Append(Str(s));
  return seq;
}

Node StrMap(const std::map<std::string, std::string>& m) {
  Node n = Node::Mapping();
  for (const auto& [k, v] : m) n.Set(k, Str(v));
  return n;
}

// The run priorities from the trial's child down to the component: the start order.
std::vector<int> PriorityKey(const dsl::Component& c, const dsl::Component& root) {
  std::vector<int> key;
  for (const dsl::Component* p = &c; p != nullptr && p != &root; p = p->parent()) {
    key.push_back(p->run_priority());
  }
  std::reverse(key.begin(), key.end());
  return key;
}

// image, container_name, hostname, user, build (a Dockerfile compose builds, tagged as `image`),
// and the command.
void SetImageAndCommand(const dsl::Plugin& p, const ComposeOptions& options, Node* svc) {
  const dsl::ContainerSpec& s = p.spec();
  svc->Set("image", Str(s.image));
  if (!s.name.empty()) svc->Set("container_name", Str(s.name));
  if (!s.hostname.empty()) svc->Set("hostname", Str(s.hostname));
  if (!s.user.empty()) svc->Set("user", Str(s.user));
  if (auto b = options.builds.find(p.id()); b != options.builds.end()) {
    Node build = Node::Mapping();  // compose builds it, tagged as `image`
    build.Set("context", Str(b->second.context));
    build.Set("dockerfile", Str(b->second.dockerfile));
    svc->Set("build", std::move(build));
  }
  if (s.argv_is_cmd) {
    if (!s.argv.empty()) svc->Set("command", StrList(s.argv));  // the image's ENTRYPOINT stays
  } else if (!s.argv.empty()) {
    svc->Set("entrypoint", StrList({s.argv.front()}));
    svc->Set("command", StrList(std::vector<std::string>(s.argv.begin() + 1, s.argv.end())));
  }
}

// environment, labels, network mode, capabilities and limits.
void SetEnvironmentAndLimits(const dsl::ContainerSpec& s, Node* svc) {
  if (!s.env.empty()) svc->Set("environment", StrMap(s.env));
  if (!s.labels.empty()) svc->Set("labels", StrMap(s.labels));
  if (!s.network_of.empty()) svc->Set("network_mode", Str("service:" + s.network_of));
  if (s.no_network) svc->Set("network_mode", Str("none"));
  if (!s.cap_add.empty()) svc->Set("cap_add", StrList(s.cap_add));
  if (!s.cap_drop.empty()) svc->Set("cap_drop", StrList(s.cap_drop));
  if (s.no_new_privileges) svc->Set("security_opt", StrList({"no-new-privileges:true"}));
  if (s.read_only_rootfs) svc->Set("read_only", Node::Scalar("true"));
  if (s.memory_mib > 0) {
    svc->Set("mem_limit", Str(std::to_string(s.memory_mib) + "m"));
    svc->Set("memswap_limit", Str(std::to_string(s.memory_mib) + "m"));  // no swap on top
  }
  if (s.pids_limit > 0) svc->Set("pids_limit", Node::Scalar(std::to_string(s.pids_limit)));
  if (!s.networks.empty()) {
    Node nets = Node::Mapping();
    for (const dsl::Attachment& a : s.networks) {
      Node n = Node::Mapping();
      if (!a.ipv4.empty()) n.Set("ipv4_address", Str(a.ipv4));
      if (!a.aliases.empty()) n.Set("aliases", StrList(a.aliases));
      nets.Set(a.network, std::move(n));
    }
    svc->Set("networks", std::move(nets));
  }
}

// The inputs bind-mounted read-only (relative to the compose file when options say so), and the
// scratch dirs: a tmpfs writable by the image's non-root user (copy results out with
// `docker cp <container>:/swarmbox/out/truth.csv .` before `down`). The runner's volumes (where it
// copies the inputs in) are not needed: compose bind-mounts the inputs, and the scratch dirs under
// them are tmpfs here.
void SetMounts(const dsl::ContainerSpec& s, const ComposeOptions& options, Node* svc) {
  std::vector<std::string> mounts;
  for (const dsl::InputFile& in : s.inputs) {
    std::string host = in.host_path;
    if (!options.host_prefix.empty() && host.rfind(options.host_prefix, 0) == 0) {
      host = options.relative_prefix + host.substr(options.host_prefix.size());
    }
    mounts.push_back(host + ":" + in.container_path + ":ro");
  }
  if (!mounts.empty()) svc->Set("volumes", StrList(mounts));
  std::vector<std::string> tmpfs;
  for (const std::string& dir : s.scratch_dirs) tmpfs.push_back(dir + ":mode=1777");
  for (const dsl::TmpfsMount& t : s.tmpfs) {
    const std::string size = t.size_mib > 0 ? ",size=" + std::to_string(t.size_mib) + "m" : "";
    tmpfs.push_back(t.path + ":mode=1777" + size);
  }
  if (!tmpfs.empty()) svc->Set("tmpfs", StrList(tmpfs));
}

// Start order: service i depends on the services of the closest earlier priority level.
void SetDependsOn(const std::vector<dsl::Plugin*>& plugins, const std::vector<std::vector<int>>& keys,
                  std::size_t i, Node* svc) {
  std::size_t previous = plugins.size();  // index of a service on that level; size() = none
  for (std::size_t j = 0; j < plugins.size(); ++j) {
    if (keys[j] < keys[i] && (previous == plugins.size() || keys[j] > keys[previous])) previous = j;
  }
  if (previous == plugins.size()) return;
  std::vector<std::string> deps;
  for (std::size_t j = 0; j < plugins.size(); ++j) {
    if (keys[j] == keys[previous]) deps.push_back(plugins[j]->id());
  }
  svc->Set("depends_on", StrList(deps));
}

Node ServicesNode(dsl::Trial& trial, const ComposeOptions& options) {
  std::vector<dsl::Plugin*> plugins = trial.Plugins();
  std::vector<std::vector<int>> keys;
  for (dsl::Plugin* p : plugins) keys.push_back(PriorityKey(*p, trial));
  Node services = Node::Mapping();
  for (std::size_t i = 0; i < plugins.size(); ++i) {
    const dsl::Plugin& p = *plugins[i];
    Node svc = Node::Mapping();
    SetImageAndCommand(p, options, &svc);
    SetEnvironmentAndLimits(p.spec(), &svc);
    SetMounts(p.spec(), options, &svc);
    SetDependsOn(plugins, keys, i, &svc);
    svc.Set("stop_grace_period", Str(std::to_string(p.spec().stop_timeout_s) + "s"));
    services.Set(p.id(), std::move(svc));
  }
  return services;
}

Node NetworkNode(const dsl::NetworkSpec& s) {
  Node net = Node::Mapping();
  if (!s.name.empty()) net.Set("name", Str(s.name));
  net.Set("driver", Str("bridge"));
  if (s.internal) net.Set("internal", Node::Scalar("true"));
  if (!s.labels.empty()) net.Set("labels", StrMap(s.labels));
  if (!s.subnet.empty()) {
    Node cfg = Node::Mapping();
    cfg.Set("subnet", Str(s.subnet));
    if (!s.gateway.empty()) cfg.Set("gateway", Str(s.gateway));
    Node configs = Node::Sequence();
    configs.Append(std::move(cfg));
    Node ipam = Node::Mapping();
    ipam.Set("config", std::move(configs));
    net.Set("ipam", std::move(ipam));
  }
  return net;
}

// Each line of `text` as a YAML comment ("#" alone for an empty line).
std::string CommentLines(std::string_view rest) {
  std::string header;
  while (!rest.empty()) {
    const auto nl = rest.find('\n');
    std::string_view line = rest.substr(0, nl);
    header += line.empty() ? "#\n" : "# " + std::string(line) + "\n";
    if (nl == std::string_view::npos) break;
    rest = rest.substr(nl + 1);
  }
  return header;
}

}  // namespace

std::string ComposeYaml(dsl::Trial& trial, const ComposeOptions& options) {
  Node doc = Node::Mapping();
  doc.Set("version", Str("2.4"));
  doc.Set("services", ServicesNode(trial, options));
  Node networks = Node::Mapping();
  for (dsl::Network* n : trial.Networks()) networks.Set(n->id(), NetworkNode(n->spec()));
  doc.Set("networks", std::move(networks));
  return CommentLines(options.header_comment) + yaml::Emit(doc);
}

}  // namespace swarmbox::runner
