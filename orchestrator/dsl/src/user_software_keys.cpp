#include "detail/user_software_keys.hpp"

#include <cmath>
#include <filesystem>
#include <regex>
#include <set>
#include <utility>

namespace swarmbox::dsl::detail {

namespace {

using yaml::Node;

constexpr double kAgentStepHz = 250.0;  // the agent's lockstep rate (the brain period is whole steps)

Error At(const Node& node, std::string message) {
  return Error(ErrorCode::kInvalidArgument, std::move(message), node.Where());
}

std::string Resolve(const SoftwareContext& context, const std::string& path) {
  std::filesystem::path p(path);
  if (p.is_relative()) p = std::filesystem::path(context.base_dir.empty() ? "." : context.base_dir) / p;
  std::error_code ec;
  std::filesystem::path abs = std::filesystem::absolute(p, ec);
  return (ec ? p : abs).lexically_normal().string();
}

// The file at `key` has the expected kind; returns its absolute host path.
Result<std::string> CheckFile(const Node& key, const std::string& what, const std::string& path,
                              FileKind expected, const std::string& hint, const SoftwareContext& context) {
  if (path.empty()) return At(key, what + " must not be empty");
  const std::string resolved = Resolve(context, path);
  if (!context.check_files) return resolved;
  const FileKind kind = context.file_kind ? context.file_kind(resolved) : ProbeFileKind(resolved);
  if (kind == expected) return resolved;
  if (kind == FileKind::kMissing) {
    return At(key, what + " '" + path + "' not found (no file " + resolved +
                       "; paths are relative to the trial file's folder)");
  }
  return At(key, what + " '" + path + "' is " + std::string(FileKindName(kind)) + " (" + resolved +
                     "), expected " + std::string(FileKindName(expected)) + hint);
}

// An image reference as `docker image ls` names it: no spaces, not empty. Never pulled.
Status CheckImageReference(const Node& key, const std::string& ref) {
  bool ok = !ref.empty();
  for (char c : ref) ok = ok && c > ' ' && c != '\\' && c != '"';
  if (!ok) return At(key, "'image' must be an image reference on the engine, such as my/brain:1 (no spaces)");
  return Ok{};
}

// `args:` of a process: a list of scalars (numbers are taken as written).
Result<std::vector<std::string>> DecodeArgList(const Node& node, const std::string& what) {
  std::vector<std::string> out;
  if (node.is_null()) return out;
  if (!node.is_sequence()) return At(node, "'args' of " + what + " must be a list of strings, e.g. [--radius-m, \"6\"]");
  for (const Node& item : node.items()) {
    if (!item.is_scalar()) return At(item, "'args' of " + what + " must be a list of strings (this item is not one)");
    out.push_back(item.scalar());
  }
  return out;
}

// Which of the source keys is given: exactly one.
struct Source {
  std::string key;     // "" = none
  std::string value;
  const Node* node = nullptr;
};
Result<Source> OneSource(const Node& mapping, std::initializer_list<const char*> keys, const std::string& what) {
  Source found;
  for (const char* key : keys) {
    const Node* n = mapping.Find(key);
    if (n == nullptr) continue;
    if (found.node != nullptr) {
      return At(*n, what + " has both '" + found.key + "' and '" + key + "': give exactly one source");
    }
    if (!n->is_scalar()) return At(*n, "'" + std::string(key) + "' must be a string");
    found = {key, n->scalar(), n};
  }
  if (found.node == nullptr) {
    std::string list;
    for (const char* key : keys) list += (list.empty() ? "" : ", ") + std::string(key);
    return At(mapping, what + " needs one of " + list);
  }
  return found;
}

bool IsComponentName(std::string_view s) {
  if (s.empty() || s.size() > 32 || !(s[0] >= 'a' && s[0] <= 'z')) return false;
  for (char c : s) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-')) return false;
  }
  return true;
}

bool IsEnvName(std::string_view s) {
  if (s.empty() || (s[0] >= '0' && s[0] <= '9')) return false;
  for (char c : s) {
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) return false;
  }
  return true;
}

// Ids the trial's tree, logs and end conditions already use.
constexpr const char* kReservedNames[] = {"physics", "raft_leader", "sim", "mesh", "drones", "sidecars",
                                          "faults", "components", "brains", "orchestrator", "user"};

}  // namespace

namespace {

// library: needs a name; its args a mapping (they become --brain-args JSON).
Status DecodeLibraryBrain(const Node& node, const Node& key, const Node* args, const SoftwareContext& context,
                          BrainSpec* brain) {
  brain->kind = BrainKind::kLibrary;
  if (brain->name.empty()) {
    return At(node, "a library brain needs 'name': the SWARMBOX_BRAIN name in the library");
  }
  auto path = CheckFile(key, "brain library", brain->path, FileKind::kElfShared,
                        " (a MODULE library, e.g. swarmbox_add_brain)", context);
  if (!path) return path.error();
  brain->host_path = *path;
  if (args != nullptr && !args->is_null()) {
    if (!args->is_mapping()) {
      return At(*args, "'args' of a library brain must be a mapping, e.g. {radius_m: 6} (it becomes --brain-args JSON)");
    }
    brain->args = *args;
  }
  return Ok{};
}

// program, dockerfile or image: one program, no name; its args a list.
Status DecodeProgramBrain(const Node& node, const Node& key, const std::string& source_key, const Node* args,
                          const SoftwareContext& context, BrainSpec* brain) {
  if (const Node* name = node.Find("name")) {
    return At(*name, "'name' belongs to library brains (a " + source_key + " brain is one program)");
  }
  if (source_key == "program") {
    brain->kind = BrainKind::kProgram;
    auto path = CheckFile(key, "brain program", brain->path, FileKind::kElfExecutable,
                          " (it is packed into an image with its shared libraries)", context);
    if (!path) return path.error();
    brain->host_path = *path;
  } else if (source_key == "dockerfile") {
    brain->kind = BrainKind::kDockerfile;
    auto path = CheckFile(key, "brain dockerfile", brain->path, FileKind::kOther, "", context);
    if (!path) return path.error();
    brain->host_path = *path;
  } else {
    brain->kind = BrainKind::kImage;
    SWARMBOX_TRY(CheckImageReference(key, brain->path));
  }
  if (args != nullptr) {
    auto list = DecodeArgList(*args, "a " + source_key + " brain");
    if (!list) return list.error();
    if (!args->is_null()) brain->args = *args;
  }
  return Ok{};
}

Status CheckBrainRate(const Node& node, const BrainSpec& brain) {
  if (const Node* rate = node.Find("rate_hz")) {
    const double steps = brain.rate_hz > 0 ? kAgentStepHz / brain.rate_hz : 0;
    if (!(brain.rate_hz > 0) || brain.rate_hz > kAgentStepHz || std::fabs(steps - std::round(steps)) > 1e-9) {
      return At(*rate, "'rate_hz' must divide the agent's 250 Hz step into whole steps (250, 125, 50, 25, 10, ...)");
    }
  }
  return Ok{};
}

Status DecodeOffboard(const Node& offboard, BrainSpec* brain) {
  if (offboard.is_null()) return Ok{};
  yaml::MapReader o(offboard, "offboard");
  int timeout_ms = 0;
  int hold_ms = 0;
  o.Optional("timeout_ms", &timeout_ms).Optional("hold_ms", &hold_ms);
  SWARMBOX_TRY(o.Finish());
  if (const Node* t = offboard.Find("timeout_ms")) {
    if (timeout_ms <= 0) return At(*t, "'timeout_ms' must be > 0 [simulated ms]");
    brain->offboard.timeout_ms = timeout_ms;
  }
  if (const Node* h = offboard.Find("hold_ms")) {
    if (hold_ms < 0) return At(*h, "'hold_ms' must be >= 0 [simulated ms]");
    brain->offboard.hold_ms = hold_ms;
  }
  return Ok{};
}

}  // namespace

Result<BrainSpec> DecodeBrain(const Node& node, const SoftwareContext& context) {
  BrainSpec brain;
  brain.mark = node.mark();
  if (node.is_null()) return brain;
  if (node.is_scalar()) {
    if (node.scalar() == "builtin") return brain;
    return At(node, "'brain' must be builtin or a mapping with one of library, program, dockerfile, image "
                    "(got '" + node.scalar() + "')");
  }
  if (!node.is_mapping()) return At(node, "'brain' must be builtin or a mapping {library|program|dockerfile|image: ...}");
  yaml::MapReader r(node, "brain");
  std::string unused;
  r.Optional("library", &unused).Optional("program", &unused).Optional("dockerfile", &unused)
      .Optional("image", &unused).Optional("name", &brain.name).Optional("rate_hz", &brain.rate_hz);
  const Node* args = r.Child("args");
  const Node* offboard = r.Child("offboard");
  SWARMBOX_TRY(r.Finish());
  auto source = OneSource(node, {"library", "program", "dockerfile", "image"}, "'brain'");
  if (!source) return source.error();
  brain.path = source->value;
  if (source->key == "library") {
    SWARMBOX_TRY(DecodeLibraryBrain(node, *source->node, args, context, &brain));
  } else {
    SWARMBOX_TRY(DecodeProgramBrain(node, *source->node, source->key, args, context, &brain));
  }
  SWARMBOX_TRY(CheckBrainRate(node, brain));
  if (offboard != nullptr) SWARMBOX_TRY(DecodeOffboard(*offboard, &brain));
  return brain;
}

namespace {

Status CheckComponentName(const Node& name_node, const std::string& name, const std::vector<UserComponentSpec>& out,
                          const std::set<std::string>& taken) {
  if (!IsComponentName(name)) {
    return At(name_node, "component name '" + name +
                             "' must be 1-32 characters of a-z, 0-9, '_', '-', starting with a letter");
  }
  for (const UserComponentSpec& other : out) {
    if (other.name == name) return At(name_node, "component name '" + name + "' is used twice");
  }
  if (taken.count(name) > 0) {
    return At(name_node, "component name '" + name +
                             "' is taken by the trial (a drone, a drone's brain or sidecar, or one of "
                             "physics, raft_leader, sim, mesh, drones, sidecars, faults, components, brains, "
                             "orchestrator, user)");
  }
  return Ok{};
}

// image, program or dockerfile: exactly one.
Status DecodeComponentSource(const Node& item, const SoftwareContext& context, UserComponentSpec* c) {
  auto source = OneSource(item, {"image", "program", "dockerfile"}, "component '" + c->name + "'");
  if (!source) return source.error();
  c->ref = source->value;
  if (source->key == "image") {
    c->source = ComponentSource::kImage;
    return CheckImageReference(*source->node, c->ref);
  }
  if (source->key == "program") {
    c->source = ComponentSource::kProgram;
    auto path = CheckFile(*source->node, "component program", c->ref, FileKind::kElfExecutable,
                          " (it is packed into an image with its shared libraries)", context);
    if (!path) return path.error();
    c->host_path = *path;
    return Ok{};
  }
  c->source = ComponentSource::kDockerfile;
  auto path = CheckFile(*source->node, "component dockerfile", c->ref, FileKind::kOther, "", context);
  if (!path) return path.error();
  c->host_path = *path;
  return Ok{};
}

Status DecodeComponentEnv(const Node& env, UserComponentSpec* c) {
  if (env.is_null()) return Ok{};
  if (!env.is_mapping()) return At(env, "'env' must be a mapping of NAME: value");
  for (const auto& [key, v] : env.entries()) {
    const std::string& k = key.scalar();
    if (!IsEnvName(k)) return At(v, "environment variable name '" + k + "' must be [A-Za-z_][A-Za-z0-9_]*");
    if (!v.is_scalar()) return At(v, "the value of '" + k + "' must be a string");
    c->env[k] = v.scalar();
  }
  return Ok{};
}

Status DecodeComponentNetworks(const Node& networks, const TrialSpec& spec, UserComponentSpec* c) {
  if (networks.is_null()) return Ok{};
  if (!networks.is_sequence()) return At(networks, "'networks' must be a list of sim, mesh (or empty: none)");
  for (const Node& n : networks.items()) {
    const std::string net = n.is_scalar() ? n.scalar() : std::string();
    if (net != "sim" && net != "mesh") {
      return At(n, "unknown network '" + net + "' (expected sim, the physics/agents bus, or mesh, the netem radio)");
    }
    if (net == "mesh" && spec.radio.model != RadioModel::kNetem) {
      return At(n, "network 'mesh' exists with radio.model netem only (this trial's radio is the simulated channel)");
    }
    for (const std::string& seen : c->networks) {
      if (seen == net) return At(n, "network '" + net + "' is listed twice");
    }
    c->networks.push_back(net);
  }
  return Ok{};
}

// `priority` in range and `ready` a non-empty regular expression.
Status CheckPriorityAndReady(const Node& item, const UserComponentSpec& c) {
  if (const Node* p = item.Find("priority");
      p != nullptr && (c.priority < kMinComponentPriority || c.priority > kMaxComponentPriority)) {
    return At(*p, "'priority' must be in [" + std::to_string(kMinComponentPriority) + ", " +
                      std::to_string(kMaxComponentPriority) + "] (the drones are " +
                      std::to_string(kDronesPriority) + ")");
  }
  if (const Node* ready = item.Find("ready")) {
    if (c.ready.empty()) return At(*ready, "'ready' must not be empty (leave it out: ready once started)");
    try {
      std::regex check(c.ready, std::regex::ECMAScript);
    } catch (const std::regex_error& ex) {
      return At(*ready, "'ready' is not a valid regular expression: " + std::string(ex.what()));
    }
  }
  return Ok{};
}

Status DecodeComponentCollect(const Node& collect, UserComponentSpec* c) {
  if (collect.is_null()) return Ok{};
  if (!collect.is_sequence()) return At(collect, "'collect' must be a list of absolute paths in the container");
  std::set<std::string> basenames;
  for (const Node& p : collect.items()) {
    const std::string path = p.is_scalar() ? p.scalar() : std::string();
    const std::string base = std::filesystem::path(path).filename().string();
    if (path.empty() || path.front() != '/' || base.empty() || base == "." || base == "..") {
      return At(p, "'collect' paths must be absolute paths of files or folders in the container, such as /tmp/out.csv");
    }
    if (!basenames.insert(base).second) {
      return At(p, "'collect' has two paths named '" + base + "' (both would be components/" + c->name + "/" + base + ")");
    }
    c->collect.push_back(path);
  }
  return Ok{};
}

// One item of `components`; `out` holds the ones before it, `taken` the trial's names.
Result<UserComponentSpec> DecodeComponent(const Node& item, const TrialSpec& spec, const SoftwareContext& context,
                                          const std::set<std::string>& taken,
                                          const std::vector<UserComponentSpec>& out) {
  UserComponentSpec c;
  c.mark = item.mark();
  yaml::MapReader r(item, "component");
  std::string unused;
  r.Required("name", &c.name).Optional("image", &unused).Optional("program", &unused)
      .Optional("dockerfile", &unused).Optional("priority", &c.priority).Optional("ready", &c.ready);
  const Node* args = r.Child("args");
  const Node* env = r.Child("env");
  const Node* networks = r.Child("networks");
  const Node* collect = r.Child("collect");
  SWARMBOX_TRY(r.Finish());
  SWARMBOX_TRY(CheckComponentName(*item.Find("name"), c.name, out, taken));
  SWARMBOX_TRY(DecodeComponentSource(item, context, &c));
  if (args != nullptr) {
    auto list = DecodeArgList(*args, "component '" + c.name + "'");
    if (!list) return list.error();
    c.args = std::move(*list);
  }
  if (env != nullptr) SWARMBOX_TRY(DecodeComponentEnv(*env, &c));
  if (networks != nullptr) SWARMBOX_TRY(DecodeComponentNetworks(*networks, spec, &c));
  SWARMBOX_TRY(CheckPriorityAndReady(item, c));
  if (collect != nullptr) SWARMBOX_TRY(DecodeComponentCollect(*collect, &c));
  return c;
}

}  // namespace

Result<std::vector<UserComponentSpec>> DecodeComponents(const Node& node, const TrialSpec& spec,
                                                        const SoftwareContext& context) {
  std::vector<UserComponentSpec> out;
  if (node.is_null()) return out;
  if (!node.is_sequence()) return At(node, "'components' must be a list of {name, image|program|dockerfile, ...}");
  if (node.items().size() > kMaxComponents) {
    return At(node, "at most " + std::to_string(kMaxComponents) + " components per trial");
  }
  std::set<std::string> taken(std::begin(kReservedNames), std::end(kReservedNames));
  for (const DroneSpec& d : spec.drones) {
    taken.insert(d.name);
    taken.insert(d.name + "-brain");
    taken.insert(d.name + "-faults");
  }
  for (const Node& item : node.items()) {
    auto c = DecodeComponent(item, spec, context, taken, out);
    if (!c) return c.error();
    out.push_back(std::move(*c));
  }
  return out;
}

}  // namespace swarmbox::dsl::detail
