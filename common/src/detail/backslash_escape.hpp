// The backslash escapes that a quoted logfmt value (logfmt.cpp, LogfmtValue) and a JSON string
// (yaml.cpp, JsonQuote) have in common: `"` `\` newline, carriage return and tab. JSON escapes
// more (other control characters); that stays in JsonQuote.
#pragma once

#include <string_view>

namespace swarmbox::detail {

// The two-character escape of `c` ("\\n" for a newline), or an empty view when `c` is none of
// the five above and is written as it is.
inline std::string_view BackslashEscape(char c) {
  switch (c) {
    case '"': return "\\\"";
    case '\\': return "\\\\";
    case '\n': return "\\n";
    case '\r': return "\\r";
    case '\t': return "\\t";
    default: return {};
  }
}

// The character a backslash followed by `c` stands for when read back ('n' -> newline, 'r', 't';
// any other `c` stands for itself, as `"` and `\` do).
inline char BackslashUnescape(char c) {
  switch (c) {
    case 'n': return '\n';
    case 'r': return '\r';
    case 't': return '\t';
    default: return c;
  }
}

}  // namespace swarmbox::detail
