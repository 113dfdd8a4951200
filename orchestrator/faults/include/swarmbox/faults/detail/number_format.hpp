// Decimal text for argv: fixed notation, trailing zeros trimmed ("0.05", "12.5", "100").
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace swarmbox::faults::detail {

// At most `decimals` digits after the point, no exponent, no trailing zeros, "-0" as "0".
std::string FormatDecimal(double value, int decimals = 6);
// Whole text must be a finite decimal number.
std::optional<double> ParseDecimal(std::string_view text);

}  // namespace swarmbox::faults::detail
