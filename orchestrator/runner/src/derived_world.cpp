#include "swarmbox/runner/derived_world.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/runner/plan.hpp"
#include "swarmbox/worlds/generator.hpp"

namespace swarmbox::runner {

namespace {

// Whether (x, y) lies inside a geofence of `size_m` centred on the origin [m].
bool Inside(double x, double y, const std::array<double, 2>& size_m) {
  return std::abs(x) <= size_m[0] / 2 && std::abs(y) <= size_m[1] / 2;
}

Status CheckInside(const yaml::Node& thing, std::string_view kind, double x, double y,
                   const std::array<double, 2>& size_m) {
  if (Inside(x, y, size_m)) return Ok{};
  const yaml::Node* id = thing.Find("id");
  const std::string name = id != nullptr && id->is_scalar() ? id->scalar() : std::string("?");
  return Error(ErrorCode::kInvalidArgument,
               std::string(kind) + " " + name + " at (" + ShortestNumber(x) + ", " + ShortestNumber(y) + ") m lies outside world_size_m [" +
                   ShortestNumber(size_m[0]) + ", " + ShortestNumber(size_m[1]) + "] (the geofence spans |x| <= X/2, |y| <= Y/2): use at least [" +
                   ShortestNumber(std::ceil(2 * std::abs(x))) + ", " + ShortestNumber(std::ceil(2 * std::abs(y))) + "]",
               thing.Where());
}

}  // namespace

Result<std::string> DeriveWorld(std::string_view world_text, std::string_view world_file,
                                const std::array<double, 2>& size_m) {
  auto doc = yaml::Parse(world_text, world_file);
  if (!doc) return doc.error();
  if (!doc->is_mapping()) {
    return Error(ErrorCode::kInvalidArgument, "a world file is a mapping {name, geofence, victims, ...}", doc->Where());
  }
  auto number = [](const yaml::Node* n) -> double {
    if (n == nullptr) return 0;
    auto v = n->AsDouble();
    return v ? *v : 0;
  };
  if (const yaml::Node* victims = doc->Find("victims"); victims != nullptr && victims->is_sequence()) {
    for (const yaml::Node& v : victims->items()) {
      SWARMBOX_TRY(CheckInside(v, "victim", number(v.Find("x_m")), number(v.Find("y_m")), size_m));
    }
  }
  if (const yaml::Node* obstacles = doc->Find("obstacles"); obstacles != nullptr && obstacles->is_sequence()) {
    for (const yaml::Node& o : obstacles->items()) {
      const yaml::Node* c = o.Find("center_m");
      if (c == nullptr || !c->is_sequence() || c->items().size() < 2) continue;  // the physics server's to report
      SWARMBOX_TRY(CheckInside(o, "obstacle", number(&c->items()[0]), number(&c->items()[1]), size_m));
    }
  }
  yaml::Node geofence = yaml::Node::Mapping();
  geofence.Set("size_x_m", yaml::Node::Scalar(ShortestNumber(size_m[0])));
  geofence.Set("size_y_m", yaml::Node::Scalar(ShortestNumber(size_m[1])));
  doc->Set("geofence", std::move(geofence));
  return "# " + std::string(world_file) + " with its geofence set to " + ShortestNumber(size_m[0]) + " x " + ShortestNumber(size_m[1]) +
         " m by the trial's world_size_m (written by the swarmbox runner)\n" + yaml::Emit(*doc);
}

Result<std::string> DerivedWorldText(const dsl::TrialSpec& spec, const std::string& trials_dir) {
  if (spec.world_generate) {
    worlds::GenerateSpec recipe = *spec.world_generate;
    if (spec.HasWorldSize()) recipe.size_m = spec.world_size_m;
    auto text = worlds::GenerateWorld(recipe, worlds::WorldSeed(recipe, spec.seed));
    if (!text) return text.error().Context("generating the world");
    return text;
  }
  const std::string source = (std::filesystem::path(trials_dir) / spec.world).string();
  std::ifstream in(source, std::ios::binary);
  if (!in) return Error(ErrorCode::kNotFound, "cannot read the world file", source);
  std::ostringstream text;
  text << in.rdbuf();
  auto derived = DeriveWorld(text.str(), source, spec.world_size_m);
  if (!derived) return derived.error().Context("world_size_m");
  return derived;
}

}  // namespace swarmbox::runner
