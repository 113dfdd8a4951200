// MakeWorldScene: the stereo pair's view of a trial's world (WorldConfig) as a StereoScene, a local
// square patch around a point, so the server renders a drone's pair over what the world holds
// there (issue #23): the ground, the obstacle boxes, the people. The bodies (drones, payloads)
// are SceneBoxes, added by the caller (StereoCapture) at their true poses.
//
//   StereoScene scene = MakeWorldScene(world, drone.x, drone.y, /*half_size_m=*/12.0, world.ground_texture_seed);
//   StereoRenderer renderer(&scene);
//
// The patch: cells of kWorldSceneCell_m on the GLOBAL grid (cell (i, j) centred at
// (i * cell, j * cell)), from round((centre - half) / cell) to round((centre + half) / cell), so
// two patches around different centres hold the same value in every cell they share (the texture
// is a function of the global cell index and the seed alone).
//   Ground: z = 0 everywhere (the worlds are flat), NIR albedo by the terrain's kind: a base
//     reflectance plus seeded value noise over three scales (one cell, 0.3 m, 1.5 m), strong on
//     rubble and gravel, medium on soil, weak on grass (the matcher's hard case); kMixed blends
//     grass and rubble by a 6 m noise. Water (Terrain::water_fraction) is not drawn.
//   Obstacles: each box raises its yaw-rotated footprint to center.z + size.z / 2 (a tree is its
//     box: the crown seen from above), textured like rubble around its own base albedo.
//   People: lying: a body-sized footprint (height_m along the heading, kVictimWidth_m across)
//     raised 0.25 m; sitting, curled and standing: smaller footprints, taller (ApproxVictimBox).
//     Each on what is under it: the median height of its footprint's cells once the obstacles
//     are drawn (a person on a heap lies on the heap; on open ground, 0 as before). The world
//     config gives people no height and the RGB camera draws them at z = 0 under the boxes
//     (render_scene.cpp): no world today puts one inside an obstacle's footprint.
//     Cover (Victim::cover) is not modelled: the body is seen whole.
//   Light: one ambient in-band irradiance for every cell (WorldAmbientWm2): full sun
//     (kSunInBandWm2) at a clear noon, scaled by the sun's elevation (the camera's sun path,
//     render_scene.cpp LightOf) and lowered towards shade (kShadeFraction) by overcast. No cast
//     shadows: obstacles do not shade the ground beside them.
//
// Pure: no clock, no state; the same arguments give the same scene. Cost: ~4 * (half / cell)^2
// cells (a 12 m half size: 230,000 cells), a few ms per patch.
#pragma once

#include <cstdint>

#include "swarmbox/physics/airframe.hpp"
#include "swarmbox/physics/stereo_scene.hpp"
#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::physics {

inline constexpr double kWorldSceneCell_m = 0.05;
inline constexpr double kLyingVictimTop_m = 0.25;  // a person lying: body and limbs ~25 cm high
inline constexpr double kVictimWidth_m = 0.5;      // shoulder width of a lying body's footprint

// The world's ambient in-band irradiance on open ground [W/m^2] (see the banner).
double WorldAmbientWm2(const WorldConfig& world);

// A person's footprint and height as a box: centre (x, y) on the ground, size along the heading
// (x) and across it (y), z = the top [m]; heading = the victim's.
Vec3 ApproxVictimBox(const Victim& victim, Vec3* centre_m);

// The bodies over the patch (StereoScene::boxes; StereoCapture adds those MayBeInView), each an
// oriented box at its true pose. Assumed NIR (940 nm) reflectances:
inline constexpr double kDroneBodyAlbedo = 0.10;  // carbon-fibre arms, black plastic, motors: dark
inline constexpr double kPayloadAlbedo = 0.45;    // a basket stretcher's orange polyethylene and aluminium
// A drone: its airframe's collision box (the physics body's geometry: frame, arms and rotors),
// centred at collision_offset_m in the body frame.
SceneBox DroneBodyBox(const Airframe& airframe, const Pose& body, std::uint64_t texture_seed);
// A payload: its box (PayloadSpec::size_m) at its centre and attitude, hanging or on the ground.
SceneBox PayloadBox(const PayloadSpec& payload, const Pose& pose, std::uint64_t texture_seed);

StereoScene MakeWorldScene(const WorldConfig& world, double centre_x_m, double centre_y_m, double half_size_m,
                           std::uint64_t seed);

}  // namespace swarmbox::physics
