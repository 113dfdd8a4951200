#include "swarmbox/common/logfmt.hpp"

#include <cinttypes>
#include <cmath>
#include <cstdio>

#include "detail/backslash_escape.hpp"
#include "swarmbox/common/format.hpp"

namespace swarmbox {

namespace {

bool NeedsQuoting(std::string_view v) {
  if (v.empty()) return true;
  for (char c : v) {
    if (c == ' ' || c == '=' || c == '"' || c == '\\' || c == '\t' || c == '\n' || c == '\r') return true;
  }
  return false;
}

}  // namespace

std::string LogfmtValue(std::string_view value) {
  if (!NeedsQuoting(value)) return std::string(value);
  std::string out = "\"";
  for (char c : value) {
    if (const std::string_view escape = detail::BackslashEscape(c); !escape.empty()) {
      out += escape;
    } else {
      out.push_back(c);
    }
  }
  out.push_back('"');
  return out;
}

LogEvent::LogEvent(double t_s, std::string_view node, std::string_view event) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "t=%.3f", t_s);
  line_.reserve(128);
  line_ += buf;
  line_ += " node=";
  line_ += LogfmtValue(node);
  line_ += " event=";
  line_ += LogfmtValue(event);
}

LogEvent& LogEvent::Add(std::string_view key, std::string_view value) {
  line_.push_back(' ');
  line_ += key;
  line_.push_back('=');
  line_ += LogfmtValue(value);
  return *this;
}

LogEvent& LogEvent::Add(std::string_view key, double value, int decimals) {
  if (std::isfinite(value)) return Add(key, std::string_view(FormatFixed(value, decimals)));
  return Add(key, std::string_view(std::isnan(value) ? "nan" : (value > 0 ? "inf" : "-inf")));
}

LogEvent& LogEvent::Add(std::string_view key, std::int64_t value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%" PRId64, value);
  return Add(key, std::string_view(buf));
}

LogEvent& LogEvent::Add(std::string_view key, std::uint64_t value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%" PRIu64, value);
  return Add(key, std::string_view(buf));
}

LogEvent& LogEvent::Add(std::string_view key, bool value) {
  return Add(key, std::string_view(value ? "true" : "false"));
}

namespace {

bool IsKeyChar(char c) { return c != ' ' && c != '=' && c != '"' && c != '\t' && c != '\r' && c != '\n'; }
bool IsValueEnd(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// The value that starts at line[*i] (after the '='), quoted or bare; *i moves past it.
std::string ReadValue(std::string_view line, std::size_t* i) {
  const std::size_t n = line.size();
  std::string value;
  if (*i >= n || line[*i] != '"') {
    const std::size_t v_start = *i;
    while (*i < n && !IsValueEnd(line[*i])) ++*i;
    return std::string(line.substr(v_start, *i - v_start));
  }
  ++*i;  // opening quote
  while (*i < n && line[*i] != '"') {
    if (line[*i] == '\\' && *i + 1 < n) {
      ++*i;
      value.push_back(detail::BackslashUnescape(line[*i]));
    } else {
      value.push_back(line[*i]);
    }
    ++*i;
  }
  if (*i < n) ++*i;  // closing quote
  return value;
}

}  // namespace

LogfmtFields ParseLogfmt(std::string_view line) {
  LogfmtFields out;
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (i < n) {
    while (i < n && !IsKeyChar(line[i])) ++i;
    std::size_t key_start = i;
    while (i < n && IsKeyChar(line[i])) ++i;
    if (i == key_start) break;
    std::string key(line.substr(key_start, i - key_start));
    if (i >= n || line[i] != '=') {
      // A bare word: only a field when the line is logfmt at all; keep it as a flag.
      out.emplace_back(std::move(key), std::string());
      continue;
    }
    ++i;  // '='
    out.emplace_back(std::move(key), ReadValue(line, &i));
  }
  // A line without a single k=v pair is not logfmt (bare words alone are prose).
  if (line.find('=') == std::string_view::npos) out.clear();
  return out;
}

std::optional<std::string> FindField(const LogfmtFields& fields, std::string_view key) {
  for (const auto& [k, v] : fields) {
    if (k == key) return v;
  }
  return std::nullopt;
}

}  // namespace swarmbox
