// Reads a recorded Docker response from tests/orchestrator/docker/data/.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace swarmbox::docker::testing {

inline std::string ReadData(const std::string& name) {
  const std::string path = std::string(SWARMBOX_DOCKER_TEST_DATA) + "/" + name;
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << "missing test data " << path;
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

}  // namespace swarmbox::docker::testing
