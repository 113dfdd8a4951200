// StereoScene: the world as the stereo pair's ray caster sees it, a height field with what the
// 940 nm-filtered mono cameras need at each cell: the height [m], the near-infrared reflectance
// and the ambient in-band irradiance (sun or shade). Boxes, heaps and people lying on the ground
// are raised cells; upright things are columns (walls and tree crowns seen from above).
//
//   StereoScene scene = MakeSurfaceScene(StereoSurface::kRubble, 48.0, /*seed=*/7);
//   AddBox(&scene, {2, 3, 0}, {1, 1, 0}, 0.8, 0.4);  // centre (x, y), size (x, y), top, albedo
//
// Pure and seeded: the same arguments give the same scene.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/physics/types.hpp"

namespace swarmbox::physics {

// In-band (940 nm notch) ambient irradiance of full sun [W/m^2] and the share left in shade.
// Assumptions, not datasheet figures: AM1.5 sunlight has ~0.3 W/m^2/nm around 940 nm (the water
// absorption band the filter sits in), over a ~40 nm filter; open shade keeps ~5 % (skylight is
// blue). physics_server/README.md "Stereo" says what depends on them.
inline constexpr double kSunInBandWm2 = 12.0;
inline constexpr double kShadeFraction = 0.05;

// A body over the height field: an oriented box (a drone's frame, a payload), hit analytically
// per ray by StereoRenderer (the nearer of it and the height field is seen). Its faces carry a
// value-noise texture fixed to the box (cells of kSceneBoxTextureCell_m and 4x that, seeded by
// texture_seed), so the matcher has something to match on it as on the ground.
struct SceneBox {
  Vec3 centre_m;                 // world ENU
  Quat attitude;                 // box -> world
  Vec3 half_size_m;              // along the box's own x, y, z
  double albedo = 0;             // NIR reflectance, the texture's mean
  std::uint64_t texture_seed = 0;
};
inline constexpr double kSceneBoxTextureCell_m = 0.05;
// The texture's amplitude, relative to the albedo: straps, struts, rivets and labels.
inline constexpr double kSceneBoxTextureAmplitude = 0.3;

// The box's bounding sphere radius [m].
double BoundingRadiusM(const SceneBox& box);
// Whether a box can be in the view of a camera at `camera_m` looking down over a patch of half
// size `half_size_m` (MakeWorldScene's): its bounding sphere within the patch's half size of the
// camera horizontally and reaching below the camera. Only such boxes go into a scene, so bodies
// far away cost the ray caster nothing.
bool MayBeInView(const SceneBox& box, const Vec3& camera_m, double half_size_m);

struct StereoScene {
  double cell_m = 0.05;
  double origin_x_m = 0;     // world x of column 0's centre (ENU)
  double origin_y_m = 0;     // world y of row 0's centre (rows go towards +y)
  cv::Mat height_m;          // CV_32F, rows x cols
  cv::Mat albedo;            // CV_32F, NIR reflectance [0, 1]
  cv::Mat ambient_w_m2;      // CV_32F, in-band ambient irradiance on the cell
  float min_height_m = 0;
  float max_height_m = 0;
  std::vector<SceneBox> boxes;  // bodies over the height field (not in min/max_height_m)

  // Bilinear height at world (x, y); outside the grid: the nearest border cell.
  float HeightAt(double x_m, double y_m) const;
  void UpdateHeightRange();
};

// The benchmark's surfaces, a square of size_m around the origin at ground level 0:
// kRubble: heaps (up to ~1.2 m) of broken concrete and bricks, strong texture, in sun;
// kConcreteShade: a flat slab of near-uniform concrete (1 % reflectance ripple), in shade;
// kSandSun: gentle dunes (0.3 m) of near-uniform sand (1 % ripple), in full sun.
enum class StereoSurface { kRubble, kConcreteShade, kSandSun };
const char* StereoSurfaceName(StereoSurface surface);
StereoScene MakeSurfaceScene(StereoSurface surface, double size_m, std::uint64_t seed);

// Raises the cells inside an axis-aligned box footprint to `top_m` (keeping higher cells) and
// gives them `albedo`: a box, a person lying (0.25 m), a stretcher, a wall, a tree crown.
void AddBox(StereoScene* scene, const Vec3& centre_m, const Vec3& size_m, double top_m, double albedo);

}  // namespace swarmbox::physics
