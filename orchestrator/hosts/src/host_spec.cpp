#include "swarmbox/hosts/host_spec.hpp"

#include <algorithm>
#include <charconv>
#include <span>

namespace swarmbox::hosts {

namespace {

constexpr std::string_view kForms =
    "expected local[?slots=N] or ssh://[user@]host[:port][?slots=N&socket=PATH&identity=KEY&"
    "known_hosts=FILE]";

Error Bad(std::string_view text, const std::string& why) {
  return Error(ErrorCode::kInvalidArgument,
               "host '" + std::string(text) + "': " + why + " (" + std::string(kForms) + ")",
               "--hosts");
}

bool ParseInt(std::string_view s, int* out) {
  const char* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, *out);
  return ec == std::errc() && p == end;
}

bool Contains(std::string_view hay, std::string_view needle) {
  return hay.find(needle) != std::string_view::npos;
}

// What ssh printed, for a message: its distinct lines (a long-lived tunnel repeats "channel N: open
// failed" once per refused connection), the first two and the last, at most 300 characters.
std::string QuoteSsh(std::string_view err) {
  std::vector<std::string> lines;
  while (!err.empty()) {
    const auto nl = err.find('\n');
    std::string line(err.substr(0, nl));
    err = nl == std::string_view::npos ? std::string_view() : err.substr(nl + 1);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    // "channel 7: open failed..." and "channel 2: open failed..." are the same news.
    if (line.rfind("channel ", 0) == 0) {
      if (auto colon = line.find(':'); colon != std::string::npos) line = "channel" + line.substr(colon);
    }
    if (line.empty() || std::find(lines.begin(), lines.end(), line) != lines.end()) continue;
    lines.push_back(std::move(line));
  }
  if (lines.size() > 3) lines.erase(lines.begin() + 2, lines.end() - 1);
  std::string out;
  for (const std::string& l : lines) out += (out.empty() ? "" : " / ") + l;
  if (out.size() > 300) out = out.substr(0, 297) + "...";
  return out;
}

}  // namespace

std::string HostSpec::name() const {
  if (kind == Kind::kLocal) return "local";
  std::string n = user.empty() ? host : user + "@" + host;
  if (port != 22) n += ":" + std::to_string(port);
  return n;
}

namespace {

constexpr int kMaxPort = 65535;
constexpr int kMaxSlots = 64;

// "[user@]host[:port]" (after "ssh://") into spec.user, spec.host and spec.port.
Status ParseSshAddress(std::string_view rest, std::string_view text, HostSpec& spec) {
  if (auto at = rest.find('@'); at != std::string_view::npos) {
    spec.user = std::string(rest.substr(0, at));
    rest = rest.substr(at + 1);
    if (spec.user.empty()) return Bad(text, "empty user name");
  }
  if (auto colon = rest.rfind(':'); colon != std::string_view::npos && rest.front() != '[') {
    if (!ParseInt(rest.substr(colon + 1), &spec.port) || spec.port < 1 || spec.port > kMaxPort) {
      return Bad(text, "bad port '" + std::string(rest.substr(colon + 1)) + "'");
    }
    rest = rest.substr(0, colon);
  }
  if (rest.empty() || rest.find('/') != std::string_view::npos) {
    return Bad(text, "missing or bad host name");
  }
  spec.host = std::string(rest);
  return Ok{};
}

// One "key=value" of the query; identity and known_hosts only mean something for ssh hosts.
Status ParseHostOption(std::string_view key, const std::string& value, std::string_view text,
                       HostSpec& spec) {
  if (key == "slots") {
    if (!ParseInt(value, &spec.slots) || spec.slots < 1 || spec.slots > kMaxSlots) {
      return Bad(text, "slots must be 1..64, got '" + value + "'");
    }
  } else if (key == "socket") {
    if (value.empty() || value.front() != '/') return Bad(text, "socket must be an absolute path");
    spec.socket = value;
  } else if (key == "identity" && spec.kind == HostSpec::Kind::kSsh) {
    spec.identity = value;
  } else if (key == "known_hosts" && spec.kind == HostSpec::Kind::kSsh) {
    spec.known_hosts = value;
  } else {
    return Bad(text, "unknown option '" + std::string(key) + "'");
  }
  return Ok{};
}

// The query after '?': "key=value" pairs joined by '&'.
Status ParseHostOptions(std::string_view query, std::string_view text, HostSpec& spec) {
  while (!query.empty()) {
    const auto amp = query.find('&');
    std::string_view kv = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view() : query.substr(amp + 1);
    const auto eq = kv.find('=');
    if (eq == std::string_view::npos) return Bad(text, "option '" + std::string(kv) + "' needs =value");
    if (Status option = ParseHostOption(kv.substr(0, eq), std::string(kv.substr(eq + 1)), text, spec);
        !option) {
      return option.error();
    }
  }
  return Ok{};
}

}  // namespace

Result<HostSpec> ParseHostSpec(std::string_view text) {
  HostSpec spec;
  spec.text = std::string(text);
  std::string_view main = text;
  std::string_view query;
  if (auto q = text.find('?'); q != std::string_view::npos) {
    main = text.substr(0, q);
    query = text.substr(q + 1);
  }
  if (main == "local") {
    spec.kind = HostSpec::Kind::kLocal;
  } else if (main.substr(0, 6) == "ssh://") {
    spec.kind = HostSpec::Kind::kSsh;
    spec.socket = std::string(kDefaultRemoteSocket);
    if (Status address = ParseSshAddress(main.substr(6), text, spec); !address) return address.error();
  } else {
    return Bad(text, "unknown kind of host");
  }
  if (Status options = ParseHostOptions(query, text, spec); !options) return options.error();
  return spec;
}

Result<std::vector<HostSpec>> ParseHostSpecs(const std::vector<std::string>& texts) {
  std::vector<HostSpec> out;
  for (const std::string& arg : texts) {
    std::string_view rest = arg;
    while (!rest.empty()) {
      const auto comma = rest.find(',');
      std::string_view one = rest.substr(0, comma);
      rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
      if (one.empty()) continue;
      auto spec = ParseHostSpec(one);
      if (!spec) return spec.error();
      for (const HostSpec& other : out) {
        if (other.name() == spec->name() && other.socket == spec->socket) {
          return Bad(one, "given twice (use ?slots=N for parallel trials on one host)");
        }
      }
      out.push_back(std::move(*spec));
    }
  }
  if (out.empty()) return Bad("", "no hosts given");
  return out;
}

std::vector<std::string> SshTunnelArgv(const HostSpec& spec, const std::string& local_socket,
                                       const std::string& control_dir) {
  std::vector<std::string> argv = {"ssh", "-N", "-o", "BatchMode=yes", "-o",
                                   "StrictHostKeyChecking=yes"};
  if (!spec.known_hosts.empty()) {
    argv.insert(argv.end(), {"-o", "UserKnownHostsFile=" + spec.known_hosts});
  }
  if (!spec.identity.empty()) {
    argv.insert(argv.end(), {"-i", spec.identity, "-o", "IdentitiesOnly=yes"});
  }
  argv.insert(argv.end(), {"-o", "ExitOnForwardFailure=yes", "-o", "StreamLocalBindUnlink=yes",
                           "-o", "ControlMaster=auto", "-o", "ControlPath=" + control_dir + "/cm-%C",
                           "-o", "ControlPersist=no", "-o", "ServerAliveInterval=5", "-o",
                           "ServerAliveCountMax=3", "-o", "ConnectTimeout=10", "-p",
                           std::to_string(spec.port), "-L", local_socket + ":" + spec.socket,
                           spec.user.empty() ? spec.host : spec.user + "@" + spec.host});
  return argv;
}

namespace {

// What ssh prints on stderr for each kind of failure, checked in this order.
constexpr std::string_view kHostKeyChangedMarkers[] = {"REMOTE HOST IDENTIFICATION HAS CHANGED"};
constexpr std::string_view kUnknownHostKeyMarkers[] = {"Host key verification failed", "No ED25519 host key",
                                                       "host key for"};
constexpr std::string_view kAuthRefusedMarkers[] = {"Permission denied (",
                                                    "Too many authentication failures"};
constexpr std::string_view kForwardFailedMarkers[] = {"open failed", "connect failed"};
constexpr std::string_view kForwardDeniedMarkers[] = {"Permission denied", "prohibited"};
constexpr std::string_view kUnreachableMarkers[] = {
    "Could not resolve hostname", "No route to host",  "Connection refused", "timed out",
    "Network is unreachable",     "Connection closed", "Broken pipe",        "Connection reset"};

// The shell's exit status for a command it cannot find.
constexpr int kCommandNotFoundExit = 127;

bool ContainsAny(std::string_view hay, std::span<const std::string_view> needles) {
  return std::any_of(needles.begin(), needles.end(),
                     [hay](std::string_view needle) { return Contains(hay, needle); });
}

std::string UnknownHostKeyMessage(const HostSpec& spec) {
  return "the host key of " + spec.name() + " is not in " +
         (spec.known_hosts.empty() ? std::string("~/.ssh/known_hosts") : spec.known_hosts) +
         " (host keys are always checked: add it, e.g. ssh-keyscan -p " + std::to_string(spec.port) + " " +
         spec.host + " after checking it)";
}

std::string AuthRefusedMessage(const HostSpec& spec) {
  return "ssh authentication to " + spec.name() + " was refused (key-only, BatchMode: is the key " +
         (spec.identity.empty() ? std::string("in ~/.ssh or the agent") : spec.identity) +
         " authorised for this user?)";
}

// The tunnel is up but the remote end of the socket forward failed.
std::string ForwardFailedMessage(const HostSpec& spec, std::string_view err) {
  const std::string socket = "the remote Docker socket " + spec.socket + " on " + spec.name();
  if (ContainsAny(err, kForwardDeniedMarkers)) {
    return socket +
           " cannot be opened by this user (permission denied: add the user to "
           "the docker group, or allow stream-local forwarding in sshd)";
  }
  return socket + " does not answer (is dockerd running there?)";
}

}  // namespace

Error ClassifySshFailure(const HostSpec& spec, std::string_view err, int exit_code) {
  const std::string who = spec.name();
  const std::string quoted = QuoteSsh(err);
  const std::string tail = quoted.empty() ? std::string() : " [ssh: " + quoted + "]";
  const auto ssh_error = [&tail](ErrorCode code, const std::string& message) {
    return Error(code, message + tail, "ssh");
  };
  if (ContainsAny(err, kHostKeyChangedMarkers)) {
    return ssh_error(ErrorCode::kInvalidArgument,
                     "the host key of " + who + " changed: check the host, then fix known_hosts");
  }
  if (ContainsAny(err, kUnknownHostKeyMarkers)) {
    return ssh_error(ErrorCode::kInvalidArgument, UnknownHostKeyMessage(spec));
  }
  if (ContainsAny(err, kAuthRefusedMarkers)) {
    return ssh_error(ErrorCode::kInvalidArgument, AuthRefusedMessage(spec));
  }
  if (ContainsAny(err, kForwardFailedMarkers)) {
    return ssh_error(ErrorCode::kInvalidArgument, ForwardFailedMessage(spec, err));
  }
  if (ContainsAny(err, kUnreachableMarkers)) {
    return ssh_error(ErrorCode::kUnavailable, "cannot reach " + who + " over ssh");
  }
  if (exit_code == kCommandNotFoundExit) {
    return Error(ErrorCode::kNotFound, "the ssh client is not installed (openssh-client)", "ssh");
  }
  return ssh_error(ErrorCode::kUnavailable,
                   "ssh to " + who + " failed" +
                       (exit_code >= 0 ? " (exit " + std::to_string(exit_code) + ")" : std::string()));
}

}  // namespace swarmbox::hosts
