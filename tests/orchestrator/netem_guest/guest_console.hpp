// The guest's report: logfmt lines the netem guest program prints on the user-mode Linux console
// (node=netem_guest), and their reader on the host. Pure.
//
//   t=3.412 node=netem_guest event=ready kernel=6.1.176 modules=12
//   t=9.870 node=netem_guest event=measured scenario=mesh probe=impaired sent=3000 received=2851 ...
//   t=9.990 node=netem_guest event=qdisc_tree scenario=mesh drone=a stage=pristine text="qdisc noqueue 0:
//   ..." t=10.200 node=netem_guest event=error scenario=mesh message="`tc qdisc replace ...` exited 2: ..."
//   t=10.300 node=netem_guest event=done scenarios=1 errors=0
//
// The console also carries the kernel's own lines (and, with UML, carriage returns); the reader
// keeps only lines of node=netem_guest.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::netem_guest {

inline constexpr std::string_view kGuestNode = "netem_guest";

inline constexpr std::string_view kEventReady = "ready";  // kernel=, modules= (count loaded)
inline constexpr std::string_view kEventApplied =
    "applied";  // scenario=, drone=, argv=, exit= (one per command)
inline constexpr std::string_view kEventMeasured = "measured";  // scenario=, probe=, the figures
inline constexpr std::string_view kEventTree = "qdisc_tree";    // scenario=, drone=, stage=, text= (tc show)
inline constexpr std::string_view kEventError = "error";        // scenario= (or "guest"), message=
inline constexpr std::string_view kEventDone = "done";          // scenarios=, errors=

struct GuestRecord {
  std::string event;
  LogfmtFields fields;                            // every field of the line, t/node/event included
  std::string Field(std::string_view key) const;  // "" when absent
};

struct GuestConsole {
  std::vector<GuestRecord> records;  // in console order

  bool done() const;
  // Every error record's scenario and message, one per line ("" when there is none).
  std::string Errors() const;
  // The first record of `event` whose `key` fields equal the given values (e.g. {{"scenario",
  // "mesh"}, {"probe", "impaired"}}), or nullptr.
  const GuestRecord* Find(std::string_view event,
                          const std::vector<std::pair<std::string_view, std::string_view>>& match) const;
  // The longest the guest went unscheduled while a probe was sending (the largest
  // send_late_max_ms of the measured records) [ms], and that probe's name; {0, ""} without any.
  std::pair<double, std::string> LongestStall() const;
};

// The node=netem_guest lines of the console text, in order.
GuestConsole ParseGuestConsole(std::string_view console);

// A record line for the console (no newline).
std::string GuestLine(double t_s, std::string_view event,
                      const std::vector<std::pair<std::string, std::string>>& fields);

}  // namespace swarmbox::netem_guest
