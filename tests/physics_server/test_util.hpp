// Shared helpers for the physics tests: shipped files, a calm test world, spawns.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "swarmbox/physics/airframe.hpp"
#include "swarmbox/physics/world.hpp"
#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::physics::testing {

inline std::string TrialsDir() { return SWARMBOX_TRIALS_DIR; }
inline std::string AirframePath(const std::string& name) { return TrialsDir() + "/airframes/" + name + ".yaml"; }
inline std::string WorldPath(const std::string& name) { return TrialsDir() + "/worlds/" + name + ".yaml"; }

inline Airframe LoadShippedAirframe(const std::string& name) {
  auto af = LoadAirframe(AirframePath(name));
  EXPECT_TRUE(af.ok()) << (af.ok() ? "" : af.error().ToString());
  return af.ok() ? *af : Airframe{};
}

// 200 x 200 m, no wind, no obstacles, no victims.
inline WorldConfig CalmWorld() {
  WorldConfig w;
  w.name = "calm";
  return w;
}

inline std::unique_ptr<World> MakeWorld(const WorldConfig& config, std::uint64_t seed = 1) {
  WorldOptions options;
  options.seed = seed;
  auto w = World::Create(config, options);
  EXPECT_TRUE(w.ok()) << (w.ok() ? "" : w.error().ToString());
  return std::move(*w);
}

// A DroneSpawn without designated initializers (GCC 12 warns on omitted fields).
inline DroneSpawn MakeSpawn(std::string name, Airframe airframe, Vec3 position_m = {}, double yaw_rad = 0,
                            double initial_throttle = 0, std::string payload = "", bool payload_attached = false) {
  DroneSpawn s;
  s.name = std::move(name);
  s.airframe = std::move(airframe);
  s.position_m = position_m;
  s.yaw_rad = yaw_rad;
  s.initial_throttle = initial_throttle;
  s.payload = std::move(payload);
  s.payload_attached = payload_attached;
  return s;
}

inline std::size_t Spawn(World& world, const DroneSpawn& spawn) {
  auto i = world.AddDrone(spawn);
  EXPECT_TRUE(i.ok()) << (i.ok() ? "" : i.error().ToString());
  return i.ok() ? *i : 0;
}

}  // namespace swarmbox::physics::testing
