#include "telemetry.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <utility>

#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::agent {
namespace {

std::optional<double> Number(const std::string& text) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || ptr != end) return std::nullopt;
  return v;
}

}  // namespace

TelemetryClock::TelemetryClock(double rate_hz) {
  if (rate_hz > 0.0 && std::isfinite(rate_hz)) period_ns_ = std::max<std::int64_t>(1, std::llround(1e9 / rate_hz));
}

bool TelemetryClock::Due(std::int64_t sim_time_ns) {
  if (period_ns_ <= 0 || sim_time_ns < next_ns_) return false;
  // The next multiple of the period after this time (a gap skips the ones missed).
  next_ns_ = (sim_time_ns / period_ns_ + 1) * period_ns_;
  return true;
}

bus::Event EventFromLogLine(std::string_view line) {
  bus::Event e;
  for (auto& [key, value] : ParseLogfmt(line)) {
    if (key == "t") {
      if (auto t = Number(value)) {
        e.sim_time_ns = std::llround(*t * 1e9);
        continue;
      }
    } else if (key == "node" && e.node.empty()) {
      e.node = std::move(value);
      continue;
    } else if (key == "event" && e.name.empty()) {
      e.name = std::move(value);
      continue;
    }
    e.fields.push_back({std::move(key), std::move(value)});
  }
  return e;
}

void EventQueue::Push(std::string_view line) {
  std::lock_guard<std::mutex> lock(mu_);
  lines_.emplace_back(line);
}

void EventQueue::TakeInto(std::vector<bus::Event>* out) {
  std::vector<std::string> lines;
  {
    std::lock_guard<std::mutex> lock(mu_);
    lines.swap(lines_);
  }
  for (const std::string& line : lines) out->push_back(EventFromLogLine(line));
}

std::optional<bus::TelemetryLink> LinkOf(const bus::Event& event) {
  if (event.name != "link") return std::nullopt;
  bus::TelemetryLink link;
  link.rtt_ms = std::numeric_limits<double>::quiet_NaN();
  bool have_peer = false, have_loss = false;
  for (const bus::KeyValue& kv : event.fields) {
    if (kv.key == "peer") {
      link.peer = kv.value;
      have_peer = !kv.value.empty();
    } else if (kv.key == "loss") {
      if (auto v = Number(kv.value)) {
        link.loss = *v;
        have_loss = true;
      }
    } else if (kv.key == "rtt_ms_mean") {
      if (auto v = Number(kv.value)) link.rtt_ms = *v;
    }
  }
  if (!have_peer || !have_loss) return std::nullopt;
  return link;
}

void SectorsOf(const std::vector<raft::Sector>& sectors, std::vector<bus::TelemetrySector>* out) {
  out->clear();
  for (const raft::Sector& s : sectors) {
    out->push_back({s.drone, {s.x_min_m, s.y_min_m, s.x_max_m, s.y_min_m, s.x_max_m, s.y_max_m, s.x_min_m, s.y_max_m}});
  }
}

}  // namespace swarmbox::agent
