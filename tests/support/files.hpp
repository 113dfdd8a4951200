// Files for tests: a fresh temporary directory, and a whole file read back.
#pragma once

#include <string>

namespace swarmbox::testing {

// A fresh, empty directory /tmp/<prefix>XXXXXX; "" when it cannot be made. The caller removes it.
std::string MakeTempDir(const std::string& prefix);

// The whole content of `path`; "" when it cannot be read.
std::string ReadWholeFile(const std::string& path);

}  // namespace swarmbox::testing
