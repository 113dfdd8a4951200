// Splitting text on a one-character separator, keeping empty pieces (a CSV row's cells, a dotted
// key's parts).
//
//   SplitOn("a,,b", ',') == {"a", "", "b"};  SplitOn("", ',') == {""};  SplitOn("x.", '.') == {"x", ""}
#pragma once

#include <string_view>
#include <vector>

namespace swarmbox {

// The pieces of `text` between occurrences of `separator`: always one more than the separators
// (so at least one, possibly empty). The views point into `text`, which must outlive them.
inline std::vector<std::string_view> SplitOn(std::string_view text, char separator) {
  std::vector<std::string_view> pieces;
  std::size_t start = 0;
  while (true) {
    const std::size_t at = text.find(separator, start);
    if (at == std::string_view::npos) {
      pieces.push_back(text.substr(start));
      return pieces;
    }
    pieces.push_back(text.substr(start, at - start));
    start = at + 1;
  }
}

}  // namespace swarmbox
