#include "swarmbox/runner/start_progress.hpp"

#include <cstdio>

namespace swarmbox::runner {

std::optional<std::string> StartProgress::Count(Counter& c, const char* what, double wall_s) {
  ++c.n;
  const std::string count = std::string(what) + " " + std::to_string(c.n) + "/" + std::to_string(total_);
  if (c.n == total_) {
    char in[48];
    std::snprintf(in, sizeof in, " in %.1f s", wall_s);
    c.last_line_s = wall_s;
    c.all_s = wall_s;
    return count + in;
  }
  if (c.n > 1 && wall_s - c.last_line_s < every_s_) return std::nullopt;
  c.last_line_s = wall_s;
  return count;
}

}  // namespace swarmbox::runner
