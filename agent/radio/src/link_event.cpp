#include "swarmbox/radio/link_event.hpp"

#include <charconv>
#include <system_error>

namespace swarmbox::radio {
namespace {

template <typename T>
std::optional<T> Number(const LogfmtFields& fields, std::string_view key) {
  const std::optional<std::string> text = FindField(fields, key);
  if (!text || text->empty()) return std::nullopt;
  T value{};
  const char* end = text->data() + text->size();
  const auto [ptr, ec] = std::from_chars(text->data(), end, value);
  if (ec != std::errc() || ptr != end) return std::nullopt;
  return value;
}

}  // namespace

LogEvent FormatLinkEvent(double sim_t_s, std::string_view self, const LinkWindow& window) {
  LogEvent e(sim_t_s, self, kLinkEvent);
  e.Add("peer", window.peer)
      .Add("sent", window.sent)
      .Add("received", window.received)
      .Add("loss", window.loss(), 4)
      .Add("late", window.late)
      .Add("dup", window.duplicates);
  if (window.received > 0) {
    e.Add("rtt_ms_mean", window.rtt.mean_ms, 2)
        .Add("rtt_ms_sd", window.rtt.sd_ms, 2)
        .Add("rtt_ms_p50", window.rtt.p50_ms, 2)
        .Add("rtt_ms_p99", window.rtt.p99_ms, 2)
        .Add("rtt_ms_max", window.rtt.max_ms, 2);
  }
  return e;
}

std::optional<LinkLine> ParseLinkLine(std::string_view line) {
  const LogfmtFields fields = ParseLogfmt(line);
  if (FindField(fields, "event") != std::string(kLinkEvent)) return std::nullopt;
  LinkLine out;
  auto node = FindField(fields, "node");
  auto peer = FindField(fields, "peer");
  auto t = Number<double>(fields, "t");
  auto sent = Number<std::uint64_t>(fields, "sent");
  auto received = Number<std::uint64_t>(fields, "received");
  auto loss = Number<double>(fields, "loss");
  if (!node || !peer || !t || !sent || !received || !loss) return std::nullopt;
  out.t_s = *t;
  out.node = std::move(*node);
  out.peer = std::move(*peer);
  out.sent = *sent;
  out.received = *received;
  out.loss = *loss;
  out.late = Number<std::uint64_t>(fields, "late").value_or(0);
  out.duplicates = Number<std::uint64_t>(fields, "dup").value_or(0);
  auto mean = Number<double>(fields, "rtt_ms_mean");
  auto p50 = Number<double>(fields, "rtt_ms_p50");
  auto p99 = Number<double>(fields, "rtt_ms_p99");
  if (mean && p50 && p99) {
    out.has_rtt = true;
    out.rtt_ms_mean = *mean;
    out.rtt_ms_p50 = *p50;
    out.rtt_ms_p99 = *p99;
    out.rtt_ms_sd = Number<double>(fields, "rtt_ms_sd").value_or(0.0);
    out.rtt_ms_max = Number<double>(fields, "rtt_ms_max").value_or(*p99);
  }
  return out;
}

}  // namespace swarmbox::radio
