#include "swarmbox/raft_service/raft_node_options.hpp"

#include <charconv>
#include <string_view>

#include "swarmbox/bus/topics.hpp"

namespace swarmbox::raft_service {
namespace {

Error Bad(const std::string& msg) { return Error(ErrorCode::kInvalidArgument, msg); }

template <typename T>
Result<T> ParseNumber(const std::string& flag, const std::string& value) {
  T v{};
  const char* end = value.data() + value.size();
  auto [p, ec] = std::from_chars(value.data(), end, v);
  if (ec != std::errc() || p != end || value.empty()) {
    return Bad(flag + ": not a number: '" + value + "'");
  }
  return v;
}

std::vector<std::string> SplitComma(const std::string& s) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= s.size()) {
    const std::size_t comma = s.find(',', start);
    const std::size_t end = comma == std::string::npos ? s.size() : comma;
    out.push_back(s.substr(start, end - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

std::string RaftNodeUsage() {
  return "usage: swarmbox-raft-node --name NAME --members A,B,C --data-dir DIR [--domain N]\n"
         "         [--interface lo] [--middleware cyclonedds|fastdds] [--seed N]\n"
         "         [--propose-every-ms N] [--duration-s S] [--tick-ms N] [--heartbeat-ms N]\n"
         "         [--election-timeout-ms N]\n";
}

namespace {

bool IsNumberFlag(const std::string& flag) {
  return flag == "--domain" || flag == "--seed" || flag == "--propose-every-ms" ||
         flag == "--duration-s" || flag == "--tick-ms" || flag == "--heartbeat-ms" ||
         flag == "--election-timeout-ms";
}

// One of the IsNumberFlag flags with its value.
Status ApplyNumberFlag(const std::string& flag, const std::string& v, RaftNodeOptions* o) {
  if (flag == "--seed") {
    auto n = ParseNumber<std::uint64_t>(flag, v);
    if (!n) return n.error();
    o->driver.seed = *n;
    return Ok{};
  }
  if (flag == "--duration-s") {
    auto n = ParseNumber<double>(flag, v);
    if (!n) return n.error();
    if (!(*n >= 0)) return Bad("--duration-s: must be >= 0");
    o->duration_s = *n;
    return Ok{};
  }
  auto n = ParseNumber<int>(flag, v);
  if (!n) return n.error();
  if (flag == "--propose-every-ms" && *n < 0) return Bad("--propose-every-ms: must be >= 0");
  int& field = flag == "--domain"             ? o->domain
               : flag == "--propose-every-ms" ? o->propose_every_ms
               : flag == "--tick-ms"          ? o->driver.tick_ms
               : flag == "--heartbeat-ms"     ? o->driver.heartbeat_ms
                                              : o->driver.election_timeout_ms;
  field = *n;
  return Ok{};
}

Status ApplyFlag(const std::string& flag, const std::string& v, RaftNodeOptions* o, bool* have_members) {
  if (IsNumberFlag(flag)) return ApplyNumberFlag(flag, v, o);
  if (flag == "--name") {
    o->driver.self = v;
  } else if (flag == "--members") {
    o->driver.members = SplitComma(v);
    *have_members = true;
  } else if (flag == "--data-dir") {
    o->data_dir = v;
  } else if (flag == "--interface") {
    o->interface = v;
  } else if (flag == "--middleware") {
    if (v != "cyclonedds" && v != "fastdds") {
      return Bad("--middleware: '" + v + "' is not cyclonedds or fastdds");
    }
    o->middleware = v;
  } else {
    return Bad("unknown flag '" + flag + "'");
  }
  return Ok{};
}

Status CheckOptions(const RaftNodeOptions& o, bool have_members) {
  if (o.driver.self.empty()) return Bad("--name is required");
  if (!have_members) return Bad("--members is required");
  if (o.data_dir.empty()) return Bad("--data-dir is required");
  if (auto s = bus::ValidateDroneName(o.driver.self); !s) return s.error().Context("--name");
  for (const std::string& m : o.driver.members) {
    if (auto s = bus::ValidateDroneName(m); !s) return s.error().Context("--members");
  }
  if (auto c = o.driver.ToRaftConfig(); !c) return c.error();
  return Ok{};
}

}  // namespace

Result<RaftNodeOptions> ParseRaftNodeArgs(const std::vector<std::string>& args) {
  RaftNodeOptions o;
  bool have_members = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& flag = args[i];
    if (flag == "--help" || flag == "-h") {
      o.help = true;
      return o;
    }
    if (flag.rfind("--", 0) != 0) return Bad("unexpected argument '" + flag + "'");
    if (i + 1 >= args.size()) return Bad(flag + ": missing value");
    const std::string& v = args[++i];
    if (auto s = ApplyFlag(flag, v, &o, &have_members); !s) return s.error();
  }
  if (auto s = CheckOptions(o, have_members); !s) return s.error();
  return o;
}

}  // namespace swarmbox::raft_service
