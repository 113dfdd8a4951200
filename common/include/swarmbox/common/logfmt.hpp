// logfmt events: the one-line-per-event log contract (ARCHITECTURE.md "Log events").
//
//   std::puts(LogEvent(12.34, "drone_2", "leader_elected").Add("term", 3).Add("leader", "drone_2")
//                 .str().c_str());
//   // t=12.340 node=drone_2 event=leader_elected term=3 leader=drone_2
//
// `t` is simulated seconds with millisecond resolution. Values with spaces, '=', '"' or that are
// empty are double-quoted with backslash escapes. ParseLogfmt() reads such a line back.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace swarmbox {

class LogEvent {
 public:
  LogEvent(double t_s, std::string_view node, std::string_view event);

  LogEvent& Add(std::string_view key, std::string_view value);
  LogEvent& Add(std::string_view key, const char* value) { return Add(key, std::string_view(value)); }
  LogEvent& Add(std::string_view key, const std::string& value) {
    return Add(key, std::string_view(value));
  }
  LogEvent& Add(std::string_view key, double value, int decimals = 3);
  LogEvent& Add(std::string_view key, std::int64_t value);
  LogEvent& Add(std::string_view key, int value) { return Add(key, static_cast<std::int64_t>(value)); }
  LogEvent& Add(std::string_view key, std::uint64_t value);
  LogEvent& Add(std::string_view key, bool value);

  const std::string& str() const { return line_; }

 private:
  std::string line_;
};

using LogfmtFields = std::vector<std::pair<std::string, std::string>>;

// Parses `k=v k2="quoted v" flag` into ordered pairs (a bare key gets value ""). Garbage between
// pairs is skipped, so any line can be fed in; a line with no '=' gives an empty list.
LogfmtFields ParseLogfmt(std::string_view line);
std::optional<std::string> FindField(const LogfmtFields& fields, std::string_view key);

// Quotes a value when logfmt needs it.
std::string LogfmtValue(std::string_view value);

}  // namespace swarmbox
