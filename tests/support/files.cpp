#include "support/files.hpp"

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

namespace swarmbox::testing {

std::string MakeTempDir(const std::string& prefix) {
  const std::string tmpl = "/tmp/" + prefix + "XXXXXX";
  std::vector<char> buf(tmpl.begin(), tmpl.end());
  buf.push_back('\0');
  const char* dir = ::mkdtemp(buf.data());
  return dir != nullptr ? std::string(dir) : std::string();
}

std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace swarmbox::testing
