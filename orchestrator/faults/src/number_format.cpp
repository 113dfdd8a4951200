#include "swarmbox/faults/detail/number_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace swarmbox::faults::detail {

std::string FormatDecimal(double value, int decimals) {
  char buf[64];
  const int written = std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  std::size_t n = written > 0 ? std::min(static_cast<std::size_t>(written), sizeof buf - 1) : 0;
  if (std::string_view(buf, n).find('.') != std::string_view::npos) {
    while (n > 0 && buf[n - 1] == '0') --n;
    if (n > 0 && buf[n - 1] == '.') --n;
  }
  const std::string_view text(buf, n);
  return std::string(text == "-0" ? std::string_view("0") : text);
}

std::optional<double> ParseDecimal(std::string_view text) {
  if (text.empty()) return std::nullopt;
  const std::string copy(text);
  char* end = nullptr;
  const double v = std::strtod(copy.c_str(), &end);
  if (end != copy.c_str() + copy.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace swarmbox::faults::detail
