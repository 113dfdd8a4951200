// The world as the camera draws it, built once per GroundRenderer: the ground texture (terrain,
// water, baked shadows) and the drawables in world coordinates (people by pose and clothing, the
// cover over them, distractors, trees, boxes), each a list of convex 3D polygons with a colour.
// Pure and seeded by the world's ground_texture_seed: the same config gives the same scene.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::physics::detail {

// How a part warms in the thermal camera (detail/thermal_scene.cpp): solids (ground, rock,
// concrete, wood) and thin sheets (fabric, plastic: a tarp, a backpack, a cone) by the sunlight
// they absorb, vegetation hardly (it transpires), a person's clothing, skin and hair also by the
// body's heat from inside.
enum class Heat : std::uint8_t { kSolid, kSheet, kVegetation, kClothing, kSkin, kHair };

// A convex polygon (the convex hull of its points once projected) in world ENU [m].
struct Part {
  std::vector<Vec3> pts;
  cv::Scalar colour;  // BGR
  Heat heat = Heat::kSolid;
};

struct Figure {
  std::size_t victim = 0;   // index into WorldConfig::victims
  std::vector<Part> parts;  // painter's order
  std::vector<Part> cover;  // drawn over the figure; hides it
  double radius_m = 1.0;    // ground radius around (x, y) that holds the figure and its cover
  Vec3 centre_m;
  // The share of the body's warmth over the air that the clothing's surface shows (thermal):
  // one of the three measured layers (detail/thermal_scene.hpp, kClothingPass), by the victim.
  double clothing_pass = 0.274;
};

struct Drawable {
  // A box obstacle: parts[0] is the whole box (its sides), parts[1] its top; seen from above the
  // top is drawn over the sides, from below the box is one colour (kBoxBelowBgr).
  bool is_box = false;
  std::vector<Part> parts;
  double top_m = 0;         // painter's order among obstacles and trees
  bool hides_people = true;
  Vec3 centre_m;
  double radius_m = 1.0;
};

// Sun and light of the world's `lighting` (flat light when absent).
struct Light {
  bool enabled = false;
  Vec3 to_sun{0, 0, 1};       // unit vector towards the sun, ENU
  double level = 1.0;         // relative scene radiance (noon, clear = 1)
  cv::Scalar colour{1, 1, 1}; // white balance of the light (B, G, R gains)
  double shadow_factor = 1.0; // radiance in shadow / in sun
  // The two terms of `level` (noon, clear = 0.866 + 0.3): the sun's on a horizontal surface and
  // the sky's; the thermal camera's irradiance (detail/thermal_scene.cpp).
  double direct = 0.0;
  double ambient = 1.0;
};

Light LightOf(const WorldConfig& config);

struct RenderScene {
  double texel_m = 0.125;
  double origin_x_m = 0;   // world x of texel column 0's left edge
  double top_y_m = 0;      // world y of texel row 0's top edge
  cv::Mat texture;         // CV_8UC3 (a thermal scene: CV_32F, kelvin)
  // Per texel, 0..255: the share of vegetation, of water (255) or mud, and of the sun's direct
  // light withheld by a shadow: what the thermal scene needs of the ground (ThermalSceneOf).
  cv::Mat vegetation, wet, shadow;
  // Where no texture is drawn: the sky, a box from below, the view from under the ground.
  cv::Scalar sky{235, 206, 135}, box_below{90, 95, 100}, underground{40, 60, 70};
  Light light;
  std::vector<Figure> figures;
  std::vector<Drawable> flats;      // distractors: drawn under people
  std::vector<Drawable> obstacles;  // boxes and trees, sorted by top height
};

RenderScene BuildScene(const WorldConfig& config);

}  // namespace swarmbox::physics::detail
