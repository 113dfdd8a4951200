// The agent's telemetry for the recording (bus::Telemetry on sim/telemetry, record/): what only
// the agent knows, every 1/rate_hz of simulated time, plus every log event it printed since the
// previous one. Nothing in the agent waits for it or decides on it: the node fills a Telemetry
// from what it already has and publishes it after the step's answer.
//
// The pure pieces live here (tested without DDS):
//   TelemetryClock  when the next one is due (simulated time);
//   EventQueue      the agent's logfmt lines (a LogTee on its log stream hands them over, from
//                   whichever part printed them), parsed into bus::Events;
//   LinkOf          an event=link line as a measured link (the probe's loss and mean RTT);
//   SectorsOf       the committed plan's sectors as polygons.
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/bus/messages.hpp"
#include "swarmbox/raft/mission_command.hpp"

namespace swarmbox::agent {

class TelemetryClock {
 public:
  // rate_hz <= 0: never due.
  explicit TelemetryClock(double rate_hz);
  // True at the first step at or after each multiple of the period (t = 0 included).
  bool Due(std::int64_t sim_time_ns);
  bool enabled() const { return period_ns_ > 0; }

 private:
  std::int64_t period_ns_ = 0;
  std::int64_t next_ns_ = 0;
};

// A logfmt event line (`t=12.340 node=scout_1 event=link peer=scout_2 ...`) as a bus::Event: t
// [s] -> sim_time_ns, node, event -> name, every other pair a field in line order. A line
// without `event` keeps name "" (and every pair as a field).
bus::Event EventFromLogLine(std::string_view line);

// The agent's log lines since the last Take, as events. Push is thread-safe (a LogTee callback).
class EventQueue {
 public:
  void Push(std::string_view line);
  // Appends the queued events to *out in the order they were printed, and empties the queue.
  void TakeInto(std::vector<bus::Event>* out);

 private:
  std::mutex mu_;
  std::vector<std::string> lines_;
};

// An event=link event (radio/link_event.hpp) as a measured link: peer, loss, rtt_ms_mean (NaN
// when nothing was answered in the window). nullopt for any other event or a malformed one.
std::optional<bus::TelemetryLink> LinkOf(const bus::Event& event);

// Each sector's rectangle as a polygon (x_min,y_min  x_max,y_min  x_max,y_max  x_min,y_max).
void SectorsOf(const std::vector<raft::Sector>& sectors, std::vector<bus::TelemetrySector>* out);

}  // namespace swarmbox::agent
