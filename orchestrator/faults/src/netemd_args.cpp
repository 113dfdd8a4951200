#include "swarmbox/faults/netemd_args.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

#include "swarmbox/faults/detail/number_format.hpp"

namespace swarmbox::faults {
namespace {

Error Bad(const std::string& flag, const std::string& why) {
  return Error(ErrorCode::kInvalidArgument, flag + ": " + why, "swarmbox-netemd run");
}

template <typename T>
Status ParseInt(const std::string& flag, const std::string& text, T min, T max, T* out) {
  long long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || value < static_cast<long long>(min) ||
      value > static_cast<long long>(max)) {
    return Bad(flag, "expected an integer in [" + std::to_string(min) + ", " + std::to_string(max) +
                         "], got '" + text + "'");
  }
  *out = static_cast<T>(value);
  return Ok{};
}

Status ParseFraction(const std::string& flag, const std::string& text, double* out) {
  auto v = detail::ParseDecimal(text);
  if (!v || !(*v >= 0.0 && *v <= 1.0)) return Bad(flag, "expected a fraction in [0, 1], got '" + text + "'");
  *out = *v;
  return Ok{};
}

}  // namespace

std::vector<std::string> NetemdRunArgv(const std::string& program, const NetemdArgs& a) {
  std::vector<std::string> argv = {
      program,
      "run",
      "--queue", std::to_string(a.queue),
      "--delay-us", std::to_string(a.delay.delay_us),
      "--jitter-us", std::to_string(a.delay.jitter_us),
      "--distribution", std::string(DistributionName(a.delay.distribution)),
      "--correlation", detail::FormatDecimal(a.delay.correlation),
      "--reorder", detail::FormatDecimal(a.delay.reorder),
      "--reorder-correlation", detail::FormatDecimal(a.delay.reorder_correlation),
      "--reorder-gap", std::to_string(a.delay.reorder_gap),
      "--seed", std::to_string(a.seed),
      "--queue-maxlen", std::to_string(a.queue_maxlen),
  };
  if (!a.pidfile.empty()) {
    argv.push_back("--pidfile");
    argv.push_back(a.pidfile);
  }
  if (a.daemonize) argv.push_back("--daemonize");
  if (a.gilbert_elliott) {
    const GilbertElliott& g = *a.gilbert_elliott;
    argv.insert(argv.end(), {"--ge-p", detail::FormatDecimal(g.p), "--ge-r", detail::FormatDecimal(g.r),
                             "--ge-loss-bad", detail::FormatDecimal(g.loss_bad), "--ge-loss-good",
                             detail::FormatDecimal(g.loss_good)});
  }
  if (a.corrupt > 0.0) argv.insert(argv.end(), {"--corrupt", detail::FormatDecimal(a.corrupt)});
  return argv;
}

std::vector<std::string> NetemdStopArgv(const std::string& program, const std::string& pidfile) {
  return {program, "stop", "--pidfile", pidfile};
}

namespace {

// What the run flags fill in. The Gilbert-Elliott model counts only when all four --ge-* flags
// are given.
struct RunArgsBuilder {
  NetemdArgs args;
  bool have_queue = false;
  GilbertElliott ge;
  unsigned ge_flags = 0;  // one bit per --ge-* flag seen
};

constexpr std::int64_t kMaxDelayUs = 600LL * 1000 * 1000;  // ten minutes
constexpr std::uint16_t kMaxQueueNumber = 65535;           // NFQUEUE numbers are 16 bits
constexpr std::uint32_t kMaxReorderGap = 1000000;
constexpr unsigned kAllGeFlags = 0b1111;

Status ParseGeFraction(const std::string& flag, const std::string& value, double GilbertElliott::*field,
                       unsigned bit, RunArgsBuilder& b) {
  SWARMBOX_TRY(ParseFraction(flag, value, &(b.ge.*field)));
  b.ge_flags |= bit;
  return Ok{};
}

using RunFlagParser = Status (*)(const std::string& flag, const std::string& value, RunArgsBuilder& b);

struct RunFlag {
  std::string_view name;
  RunFlagParser parse;
};

// Every "run" flag that takes a value (--daemonize takes none).
constexpr RunFlag kRunFlags[] = {
    {"--queue",
     [](const std::string& f, const std::string& v, RunArgsBuilder& b) -> Status {
       SWARMBOX_TRY(ParseInt<std::uint16_t>(f, v, 0, kMaxQueueNumber, &b.args.queue));
       b.have_queue = true;
       return Ok{};
     }},
    {"--delay-us",
     [](const std::string& f, const std::string& v, RunArgsBuilder& b) {
       return ParseInt<std::int64_t>(f, v, 0, kMaxDelayUs, &b.args.delay.delay_us);
     }},
    {"--jitter-us",
     [](const std::string& f, const std::string& v, RunArgsBuilder& b) {
       return ParseInt<std::int64_t>(f, v, 0, kMaxDelayUs, &b.args.delay.jitter_us);
     }},
    {"--distribution",
     [](const std::string& f, const std::string& v, RunArgsBuilder& b) -> Status {
       auto d = DistributionFromName(v);
       if (!d) return Bad(f, "expected uniform, normal, pareto or paretonormal, got '" + v + "'");
       b.args.delay.distribution = *d;
       return Ok{};
     }},
    {"--correlation", [](const std::string& f, const std::string& v,
                         RunArgsBuilder& b) { return ParseFraction(f, v, &b.args.delay.correlation); }},
    {"--reorder", [](const std::string& f, const std::string& v,
                     RunArgsBuilder& b) { return ParseFraction(f, v, &b.args.delay.reorder); }},
    {"--reorder-correlation",
     [](const std::string& f, const std::string& v, RunArgsBuilder& b) {
       return ParseFraction(f, v, &b.args.delay.reorder_correlation);
     }},
    {"--reorder-gap",
     [](const std::string& f, const std::string& v, RunArgsBuilder& b) {
       return ParseInt<std::uint32_t>(f, v, 0, kMaxReorderGap, &b.args.delay.reorder_gap);
     }},
    {"--seed",
     [](const std::string& f, const std::string& v, RunArgsBuilder& b) -> Status {
       std::int64_t seed = 0;
       SWARMBOX_TRY(ParseInt<std::int64_t>(f, v, 0, std::numeric_limits<std::int64_t>::max(), &seed));
       b.args.seed = static_cast<std::uint64_t>(seed);
       return Ok{};
     }},
    {"--queue-maxlen",
     [](const std::string& f, const std::string& v, RunArgsBuilder& b) {
       return ParseInt<std::uint32_t>(f, v, 1, kNetemdMaxQueueLen, &b.args.queue_maxlen);
     }},
    {"--ge-p", [](const std::string& f, const std::string& v,
                  RunArgsBuilder& b) { return ParseGeFraction(f, v, &GilbertElliott::p, 1U << 0, b); }},
    {"--ge-r", [](const std::string& f, const std::string& v,
                  RunArgsBuilder& b) { return ParseGeFraction(f, v, &GilbertElliott::r, 1U << 1, b); }},
    {"--ge-loss-bad",
     [](const std::string& f, const std::string& v, RunArgsBuilder& b) {
       return ParseGeFraction(f, v, &GilbertElliott::loss_bad, 1U << 2, b);
     }},
    {"--ge-loss-good",
     [](const std::string& f, const std::string& v, RunArgsBuilder& b) {
       return ParseGeFraction(f, v, &GilbertElliott::loss_good, 1U << 3, b);
     }},
    {"--corrupt", [](const std::string& f, const std::string& v,
                     RunArgsBuilder& b) { return ParseFraction(f, v, &b.args.corrupt); }},
    {"--pidfile",
     [](const std::string& f, const std::string& v, RunArgsBuilder& b) -> Status {
       if (v.empty() || v[0] != '/') return Bad(f, "expected an absolute path, got '" + v + "'");
       b.args.pidfile = v;
       return Ok{};
     }},
};

const RunFlag* FindRunFlag(std::string_view name) {
  for (const RunFlag& flag : kRunFlags) {
    if (flag.name == name) return &flag;
  }
  return nullptr;
}

}  // namespace

Result<NetemdArgs> ParseNetemdRunArgs(const std::vector<std::string>& words) {
  RunArgsBuilder b;
  for (std::size_t i = 0; i < words.size(); ++i) {
    const std::string& flag = words[i];
    if (flag == "--daemonize") {
      b.args.daemonize = true;
      continue;
    }
    if (i + 1 >= words.size()) return Bad(flag, "missing value (or unknown flag)");
    const std::string& value = words[++i];
    const RunFlag* known = FindRunFlag(flag);
    if (known == nullptr) return Bad(flag, "unknown flag");
    SWARMBOX_TRY(known->parse(flag, value, b));
  }
  if (!b.have_queue) return Bad("--queue", "required");
  if (b.ge_flags != 0 && b.ge_flags != kAllGeFlags) {
    return Bad("--ge-p", "a Gilbert-Elliott model needs all of --ge-p, --ge-r, --ge-loss-bad and --ge-loss-good");
  }
  if (b.ge_flags != 0) b.args.gilbert_elliott = b.ge;
  return b.args;
}

}  // namespace swarmbox::faults
