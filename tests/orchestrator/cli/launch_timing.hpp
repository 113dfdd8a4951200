// The pure half of `swarmbox-bench launch`: Docker's log timestamps, and the figures of one launch
// from the times the bench observed (no clock, no Docker here).
//
//   LaunchTimes t;
//   t.spawn_ns = <unix ns when `swarmbox run` / `docker-compose up` was started>;
//   t.ready_ns = {{"scout_1", ...}, ...};    // the timestamp of each agent's event=ready line
//   t.end_line_ns = ...;                     // the line the trial ended on
//   t.died_ns = {...};                       // each container's `die` event
//   LaunchFigures f = ComputeLaunchFigures(t, {"scout_1", "scout_2"});
//
// All times are Unix nanoseconds of one host's real-time clock (Docker stamps log lines and events
// with it), so they compare across processes.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace swarmbox::cli::testing {

// "2026-11-21T16:00:00.123456789Z" (RFC 3339 in UTC, as `docker logs --timestamps` writes it;
// 0-9 fraction digits) -> Unix ns. nullopt for anything else.
std::optional<std::int64_t> ParseDockerTimestampNs(std::string_view text);

// A line of a log followed with timestamps: "<timestamp> <text>" -> the time and the text.
struct StampedLine {
  std::int64_t time_ns = 0;
  std::string_view text;
};
std::optional<StampedLine> SplitStampedLine(std::string_view line);

struct LaunchTimes {
  std::int64_t spawn_ns = 0;
  std::map<std::string, std::int64_t> ready_ns;  // component -> its first event=ready line
  std::map<std::string, std::int64_t> start_ns;  // component -> its container's `start` event
  std::optional<std::int64_t> end_line_ns;        // the ending line (runs with a watcher only)
  std::vector<std::int64_t> died_ns;               // one per container that stopped
  std::optional<std::int64_t> exited_ns;           // when the launching program exited
};

struct LaunchFigures {
  std::optional<double> ready_s;       // spawn -> the last of `agents` ready; nullopt if one never was
  std::vector<std::string> not_ready;  // agents without an event=ready line
  std::optional<double> end_to_stopped_s;  // ending line -> the last container stopped
  std::optional<double> end_to_exit_s;     // ending line -> the launching program exited
};

LaunchFigures ComputeLaunchFigures(const LaunchTimes& times, const std::vector<std::string>& agents);

// From a component's container `start` event to its event=ready line; nullopt without both.
std::optional<double> StartToReady(const LaunchTimes& times, const std::string& component);

}  // namespace swarmbox::cli::testing
