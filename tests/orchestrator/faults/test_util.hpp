// Helpers for the fault tests: YAML from text, argv text, a recording CommandRunner.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/faults/command_runner.hpp"

namespace swarmbox::faults::testing {

inline yaml::Node Yaml(const std::string& text) {
  auto node = yaml::Parse(text, "trial.yaml");
  if (!node) {
    ADD_FAILURE() << node.error().ToString();
    return yaml::Node();
  }
  return *node;
}

// Each command as one line of text, for readable expectations.
inline std::vector<std::string> Lines(const std::vector<Command>& commands) {
  std::vector<std::string> out;
  for (const auto& c : commands) out.push_back(CommandText(c.argv) + (c.may_fail ? "  [may fail]" : ""));
  return out;
}

// Records every argv; answers from a script keyed by argv[0] + " " + argv[1] (default: exit 0).
class FakeCommandRunner : public CommandRunner {
 public:
  Result<CommandOutput> Run(const std::vector<std::string>& argv) override {
    calls.push_back(CommandText(argv));
    const std::string key = argv.size() > 1 ? argv[0] + " " + argv[1] : argv[0];
    if (auto it = answers.find(key); it != answers.end()) return it->second;
    return CommandOutput{};
  }
  std::vector<std::string> calls;
  std::map<std::string, CommandOutput> answers;
};

}  // namespace swarmbox::faults::testing
