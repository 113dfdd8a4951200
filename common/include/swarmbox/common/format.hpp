// Number formatting shared by log lines, brain events and the runner's progress line.
//
//   FormatFixed(1.23456, 2) == "1.23";  FormatFixed(-0.5, 0) == "-0" (printf's "%.*f", as is)
#pragma once

#include <cstdio>
#include <string>

namespace swarmbox {

// `value` with `decimals` digits after the point, exactly printf's "%.*f" (so nan prints as
// "nan" or "-nan", inf as "inf"); at most 63 characters.
inline std::string FormatFixed(double value, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

}  // namespace swarmbox
