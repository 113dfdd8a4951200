#include "json_out.hpp"

#include <charconv>
#include <cmath>
#include <iostream>

namespace swarmbox::cli::json {

yaml::Node Str(std::string_view text) { return yaml::Node::Scalar(std::string(text), {}, /*quoted=*/true); }

yaml::Node Num(double value) {
  if (!std::isfinite(value)) return yaml::Node::Null();
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), value);
  return yaml::Node::Scalar(std::string(buf, r.ptr));
}

yaml::Node Int(std::int64_t value) { return yaml::Node::Scalar(std::to_string(value)); }

yaml::Node Bool(bool value) { return yaml::Node::Scalar(value ? "true" : "false"); }

yaml::Node Strs(const std::vector<std::string>& texts) {
  yaml::Node list = yaml::Node::Sequence();
  for (const std::string& t : texts) list.Append(Str(t));
  return list;
}

void Print(const yaml::Node& node) { std::cout << yaml::EmitJson(node) << "\n"; }

}  // namespace swarmbox::cli::json
