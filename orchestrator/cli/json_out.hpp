// The machine-readable summaries of `--json` (validate, images, gc, run, experiment): one JSON
// object on stdout, built as a yaml::Node and written by yaml::EmitJson (the project's one JSON
// writer). Progress and diagnostics stay on stderr, so `swarmbox run --json ... | jq` works.
//
//   yaml::Node o = yaml::Node::Mapping();
//   o.Set("outcome", json::Str("success"));
//   o.Set("sim_s", json::Num(12.5));
//   json::Print(o);   // {"outcome":"success","sim_s":12.5}
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::cli::json {

// A JSON string (always quoted, also "1" or "true").
yaml::Node Str(std::string_view text);
// A JSON number: the shortest text that reads back as `value`; null when not finite.
yaml::Node Num(double value);
yaml::Node Int(std::int64_t value);
yaml::Node Bool(bool value);
// A JSON array of strings.
yaml::Node Strs(const std::vector<std::string>& texts);

// EmitJson(node) and a newline on std::cout.
void Print(const yaml::Node& node);

}  // namespace swarmbox::cli::json
