// --set key=value overrides on a YAML document, before it is decoded (so the strict schema checks
// the result, with marks that point at the override: "--set seed:1:1: expected an integer").
//
// The key is a dotted path. Mapping keys are created when missing; a number indexes a list
// (drones.0.pose); in a list of mappings a name selects the item whose `name` is that name
// (drones.scout_1.payload). The value is parsed as YAML, so `--set drones.0.pose=[1,2,0]` works;
// an empty value is null.
#pragma once

#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::dsl {

Status ApplyOverride(yaml::Node& document, std::string_view assignment);

}  // namespace swarmbox::dsl
