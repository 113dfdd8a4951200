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

Result<NetemdArgs> ParseNetemdRunArgs(const std::vector<std::string>& words) {
  NetemdArgs a;
  bool have_queue = false;
  GilbertElliott ge;
  int ge_flags = 0;
  for (std::size_t i = 0; i < words.size(); ++i) {
    const std::string& flag = words[i];
    if (flag == "--daemonize") {
      a.daemonize = true;
      continue;
    }
    if (i + 1 >= words.size()) return Bad(flag, "missing value (or unknown flag)");
    const std::string& v = words[++i];
    constexpr std::int64_t kMaxUs = 600LL * 1000 * 1000;
    if (flag == "--queue") {
      SWARMBOX_TRY(ParseInt<std::uint16_t>(flag, v, 0, 65535, &a.queue));
      have_queue = true;
    } else if (flag == "--delay-us") {
      SWARMBOX_TRY(ParseInt<std::int64_t>(flag, v, 0, kMaxUs, &a.delay.delay_us));
    } else if (flag == "--jitter-us") {
      SWARMBOX_TRY(ParseInt<std::int64_t>(flag, v, 0, kMaxUs, &a.delay.jitter_us));
    } else if (flag == "--distribution") {
      auto d = DistributionFromName(v);
      if (!d) return Bad(flag, "expected uniform, normal, pareto or paretonormal, got '" + v + "'");
      a.delay.distribution = *d;
    } else if (flag == "--correlation") {
      SWARMBOX_TRY(ParseFraction(flag, v, &a.delay.correlation));
    } else if (flag == "--reorder") {
      SWARMBOX_TRY(ParseFraction(flag, v, &a.delay.reorder));
    } else if (flag == "--reorder-correlation") {
      SWARMBOX_TRY(ParseFraction(flag, v, &a.delay.reorder_correlation));
    } else if (flag == "--reorder-gap") {
      SWARMBOX_TRY(ParseInt<std::uint32_t>(flag, v, 0, 1000000, &a.delay.reorder_gap));
    } else if (flag == "--seed") {
      std::int64_t seed = 0;
      SWARMBOX_TRY(ParseInt<std::int64_t>(flag, v, 0, std::numeric_limits<std::int64_t>::max(), &seed));
      a.seed = static_cast<std::uint64_t>(seed);
    } else if (flag == "--queue-maxlen") {
      SWARMBOX_TRY(ParseInt<std::uint32_t>(flag, v, 1, kNetemdMaxQueueLen, &a.queue_maxlen));
    } else if (flag == "--ge-p") {
      SWARMBOX_TRY(ParseFraction(flag, v, &ge.p));
      ge_flags |= 1;
    } else if (flag == "--ge-r") {
      SWARMBOX_TRY(ParseFraction(flag, v, &ge.r));
      ge_flags |= 2;
    } else if (flag == "--ge-loss-bad") {
      SWARMBOX_TRY(ParseFraction(flag, v, &ge.loss_bad));
      ge_flags |= 4;
    } else if (flag == "--ge-loss-good") {
      SWARMBOX_TRY(ParseFraction(flag, v, &ge.loss_good));
      ge_flags |= 8;
    } else if (flag == "--corrupt") {
      SWARMBOX_TRY(ParseFraction(flag, v, &a.corrupt));
    } else if (flag == "--pidfile") {
      if (v.empty() || v[0] != '/') return Bad(flag, "expected an absolute path, got '" + v + "'");
      a.pidfile = v;
    } else {
      return Bad(flag, "unknown flag");
    }
  }
  if (!have_queue) return Bad("--queue", "required");
  if (ge_flags != 0 && ge_flags != 0b1111) {
    return Bad("--ge-p", "a Gilbert-Elliott model needs all of --ge-p, --ge-r, --ge-loss-bad and --ge-loss-good");
  }
  if (ge_flags != 0) a.gilbert_elliott = ge;
  return a;
}

}  // namespace swarmbox::faults
