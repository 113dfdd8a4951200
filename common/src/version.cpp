#include "swarmbox/common/version.hpp"

namespace swarmbox {

std::string VersionLine(std::string_view program) {
  const BuildInfo& b = Build();
  std::string line(program);
  line += ' ';
  line += b.version;
  line += " (commit ";
  line += b.commit;
  line += ", ";
  line += b.build_type.empty() ? std::string_view("no build type") : b.build_type;
  line += ')';
  return line;
}

}  // namespace swarmbox
